# An independent reader and writer of 8- and 16-bit grey PNGs (no interlace), as lidarshop writes them:
# the CLI tests check lidarshop's masks with it, not with lidarshop itself.
import struct, zlib
def read(path):
    data = open(path, 'rb').read(); pos = 8; chunks = b''; width = height = depth = 0
    while pos < len(data):
        n = struct.unpack('>I', data[pos:pos + 4])[0]; kind = data[pos + 4:pos + 8]; body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR': width, height, depth = struct.unpack('>IIB', body[:9])
        if kind == b'IDAT': chunks += body
        pos += 12 + n
    raw = zlib.decompress(chunks); bpp = depth // 8; stride = width * bpp; rows = []; prev = bytearray(stride)
    for r in range(height):
        f = raw[r * (stride + 1)]; line = bytearray(raw[r * (stride + 1) + 1:(r + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0; b = prev[i]; c = prev[i - bpp] if i >= bpp else 0
            p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + [0, a, b, (a + b) // 2, a if pa <= pb and pa <= pc else (b if pb <= pc else c)][f]) & 255
        rows.append([int.from_bytes(line[i * bpp:(i + 1) * bpp], 'big') for i in range(width)]); prev = line
    return rows
def write(path, rows):
    raw = b''.join(b'\0' + bytes(row) for row in rows)
    chunk = lambda kind, body: struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body))
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', len(rows[0]), len(rows), 8, 0, 0, 0, 0))
                           + chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
