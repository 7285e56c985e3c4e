#!/usr/bin/env python3
"""Writes the hostile-input corpus into tests/hostile/corpus/ and its case list cases.txt.

Usage: make_corpus.py LIDARSHOP_BINARY   (run from anywhere; rewrites tests/hostile/corpus and cases.txt)
       make_corpus.py --big DIR           (writes the inputs too large for git into DIR: hostile_test.sh's {B})

Each case is one line of cases.txt: `reader|expect|arguments` where expect is `error` (one clean line on stderr
and a non-zero exit) or `ok`, and the arguments of `lidarshop` use {C} for the corpus folder, {W} for a scratch
folder and {FIFO} for a named pipe that hostile_test.sh creates (a FIFO cannot live in git). The files are
small and deterministic (fixed seeds); valid bases (PLY, PCD, E57) are converted from a 4 x 6 PTX by the binary.
"""
import json
import os
import random
import shutil
import struct
import subprocess
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, 'corpus')
cases = []


def write(name, data):
    with open(os.path.join(CORPUS, name), 'wb' if isinstance(data, bytes) else 'w') as f:
        f.write(data)
    return '{C}/' + name


def case(reader, expect, args):
    if args.startswith('info '):
        # `info` reads headers only; `info --stats` reads every point (the full reader, whose checks the
        # expectation is about). The header reader must stay clean too: a clean error or success.
        cases.append(f'{reader}|{expect}|info --stats {args[5:]}')
        cases.append(f'{reader}|{"ok" if expect == "ok" else "any"}|{args}')
        return
    cases.append(f'{reader}|{expect}|{args}')


IDENTITY = '1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n'


def ptx(rows=4, cols=6, pose=IDENTITY, point=None, header=None):
    lines = [str(cols), str(rows), '0 0 0', '1 0 0', '0 1 0', '0 0 1'] if header is None else header
    out = '\n'.join(lines) + '\n' + pose
    for c in range(cols):
        for r in range(rows):
            p = point(r, c) if point else (0.1 * c - 0.3, 5.0, 0.1 * r - 0.2)
            out += f'{p[0]} {p[1]} {p[2]} 0.5\n'
    return out


def crc32c(data):
    crc = 0xFFFFFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ (0x82F63B78 if crc & 1 else 0)
    return crc ^ 0xFFFFFFFF


def e57_logical(data):
    return b''.join(data[i:i + 1020] for i in range(0, len(data), 1024))


def e57_pages(logical):
    out = b''
    for i in range(0, len(logical), 1020):
        page = logical[i:i + 1020].ljust(1020, b'\0')
        out += page + struct.pack('>I', crc32c(page))
    return out


def png_chunk(kind, data):
    return struct.pack('>I', len(data)) + kind + data + struct.pack('>I', zlib.crc32(kind + data))


def png_image(width, height, bit_depth=1, colour_type=0, channels=1):
    """A real (zero-filled) PNG: a 1-bit grey image compresses about 400 pixels into a byte."""
    row = b'\0' * (1 + (width * channels * bit_depth + 7) // 8)
    compressor = zlib.compressobj(9)
    idat = b''.join(compressor.compress(row) for _ in range(height)) + compressor.flush()
    return (b'\x89PNG\r\n\x1a\n' + png_chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, bit_depth, colour_type, 0, 0, 0))
            + png_chunk(b'IDAT', idat) + png_chunk(b'IEND', b''))


def e57_build(scans, images=(), blobs=()):
    """An E57 file from scratch: `scans` are (name bytes, recordCount, prototype XML) whose fields must all take
    no bits (Integer minimum == maximum: no bytestream bytes), `images` are (name, blob index) photos as
    visualReferenceRepresentation entries of `blobs` (PNG bytes, each stored once)."""
    logical = bytearray(48)
    phys = lambda at: at // 1020 * 1024 + at % 1020
    blob_at = []
    for blob in blobs:
        while len(logical) % 8: logical.append(0)
        blob_at.append(phys(len(logical)))
        logical += bytes([0]) + bytes(7) + struct.pack('<Q', 16 + len(blob)) + blob
    while len(logical) % 8: logical.append(0)
    cv_at = len(logical)
    logical += bytes([1]) + bytes(7) + struct.pack('<QQQ', 32, phys(cv_at + 32), 0)
    xml = (b'<?xml version="1.0" encoding="UTF-8"?>\n<e57Root type="Structure" xmlns="http://www.astm.org/COMMIT/E57/2010-e57-v1.0">\n'
           b'<formatName type="String">ASTM E57 3D Imaging Data File</formatName>\n<guid type="String">hostile</guid>\n'
           b'<versionMajor type="Integer">1</versionMajor>\n<versionMinor type="Integer">0</versionMinor>\n'
           b'<data3D type="Vector" allowHeterogeneousChildren="1">\n')
    for i, (name, count, prototype) in enumerate(scans):
        xml += (b'<vectorChild type="Structure"><guid type="String">scan%d</guid><name type="String">%s</name>'
                b'<points type="CompressedVector" fileOffset="%d" recordCount="%d"><prototype type="Structure">%s</prototype>'
                b'<codecs type="Vector" allowHeterogeneousChildren="1"/></points></vectorChild>\n'
                % (i, name, phys(cv_at), count, prototype))
    xml += b'</data3D>\n<images2D type="Vector" allowHeterogeneousChildren="1">\n'
    for name, blob in images:
        xml += (b'<vectorChild type="Structure"><name type="String">%s</name><visualReferenceRepresentation type="Structure">'
                b'<pngImage type="Blob" fileOffset="%d" length="%d"/><imageWidth type="Integer">1</imageWidth>'
                b'<imageHeight type="Integer">1</imageHeight></visualReferenceRepresentation></vectorChild>\n'
                % (name, blob_at[blob], len(blobs[blob])))
    xml += b'</images2D>\n</e57Root>\n'
    xml_at = len(logical)
    logical += xml
    pages = (len(logical) + 1019) // 1020
    logical[0:48] = b'ASTM-E57' + struct.pack('<IIQQQQ', 1, 0, pages * 1024, phys(xml_at), len(xml), 1024)
    return e57_pages(bytes(logical))


# A point at (1, 5, 0) whose fields take no bits: any recordCount fits in no bytes.
CONSTANT_POINT = (b'<cartesianX type="Integer" minimum="1" maximum="1"/><cartesianY type="Integer" minimum="5" maximum="5"/>'
                  b'<cartesianZ type="Integer" minimum="0" maximum="0"/>')


def big_files(directory):
    """Inputs too large to keep in git, written by hostile_test.sh before its cases run ({B})."""
    os.makedirs(directory, exist_ok=True)
    # 100,000 scans of one point each in 7 MB (issue 37: 793 MB before the scans were counted).
    scan = ptx(rows=1, cols=1)
    with open(os.path.join(directory, 'scans_100k.ptx'), 'w') as f:
        f.write(scan * 100000)
    # 20,000 one-box objects in 400 KB: each object costs a mesh and an Embree geometry whatever its size.
    with open(os.path.join(directory, 'boxes_20k.json'), 'w') as f:
        f.write('{"objects": [' + ','.join(['{"primitive":"box"}'] * 20000) + ']}')


def flips(ext, base, count, rnd):
    """`count` copies of `base` with 1 to 6 random bytes replaced: a clean error or success, nothing else."""
    for i in range(count):
        data = bytearray(base)
        for _ in range(rnd.randint(1, 6)):
            data[rnd.randrange(len(data))] = rnd.randrange(256)
        case(ext, 'any', 'info ' + write(f'flip_{i}.{ext}', bytes(data)))


def main():
    if sys.argv[1] == '--big':
        big_files(sys.argv[2])
        return
    lidarshop = sys.argv[1]
    shutil.rmtree(CORPUS, ignore_errors=True)
    os.makedirs(CORPUS)
    rnd = random.Random(20)

    # ---- PTX
    good = write('good.ptx', ptx())
    case('ptx', 'ok', f'info {good}')
    bad_poses = {
        'zero': '0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1\n',
        'shear': '1 0 0 0\n0.5 1 0 0\n0 0 1 0\n0 0 0 1\n',
        'mirror': '-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n',
        'scale1e6': '1e6 0 0 0\n0 1e6 0 0\n0 0 1e6 0\n0 0 0 1\n',
        'translate1e308': '1 0 0 0\n0 1 0 0\n0 0 1 0\n1e308 0 0 1\n',
        'nan': '1 0 0 0\n0 1 0 0\n0 0 1 0\nnan 0 0 1\n',
        'last_column': '1 0 0 1\n0 1 0 0\n0 0 1 0\n0 0 0 1\n',
    }
    case('ptx', 'ok', 'info ' + write('pose_usual_layout.ptx', ptx(pose=bad_poses.pop('last_column'))))
    for name, pose in bad_poses.items():
        case('ptx', 'error', 'info ' + write(f'pose_{name}.ptx', ptx(pose=pose)))
    for name, value in {'1e38': '1e38', 'm1e38': '-1e38', 'inf': 'inf', 'nan': 'nan', '1e30': '1e30'}.items():
        case('ptx', 'error', 'info ' + write(f'point_{name}.ptx', ptx(point=lambda r, c: (value, 5, 0) if r == c == 1 else (0.1 * c, 5, 0.1 * r))))
    text = ptx()
    for cut in [0, 1, 3, 10, 30, 60, len(text) // 2, len(text) - 5]:
        case('ptx', 'error', 'info ' + write(f'truncated_{cut}.ptx', text[:cut]))
    for rows, cols in [(0, 6), (-4, 6), (268435456, 1), (65536, 65536), (4, 99999999999999999999), (4, 'abc')]:
        header = [str(cols), str(rows), '0 0 0', '1 0 0', '0 1 0', '0 0 1']
        case('ptx', 'error', 'info ' + write(f'size_{rows}_{cols}.ptx'[:40], ptx(header=header)))
    for i in range(12):
        data = bytearray(text.encode())
        for _ in range(rnd.randint(1, 8)):
            data[rnd.randrange(len(data))] = rnd.choice(b'0123456789.-e xnaif\n\x00\xff')
        expect = 'any'
        case('ptx', expect, 'info ' + write(f'flip_{i}.ptx', bytes(data)))
    case('ptx', 'error', 'info ' + write('garbage.ptx', bytes(rnd.randrange(256) for _ in range(400))))
    case('ptx', 'error', 'info ' + write('extra_column.ptx', text.replace('0.5\n', '0.5 1 2 3 4\n', 1)))
    case('ptx', 'error', 'info ' + write('color_300.ptx', text.replace('0.5\n', '0.5 300 0 0\n', 1)))
    case('ptx', 'error', 'info {FIFO}.ptx')
    case('ptx', 'error', 'info {C}/folder.ptx')
    os.makedirs(os.path.join(CORPUS, 'folder.ptx'), exist_ok=True)
    write('folder.ptx/.keep', '')
    case('ptx', 'error', 'info /dev/zero')
    case('ptx', 'error', 'info {C}/missing.ptx')

    # ---- PLY / PCD / E57 bases from the binary
    for ext in ['ply', 'pcd', 'e57']:
        subprocess.run([lidarshop, 'convert', os.path.join(CORPUS, 'good.ptx'),
                        os.path.join(CORPUS, f'good.{ext}'), '-q'], check=True)
    case('ply', 'ok', 'info {C}/good.ply')
    case('pcd', 'ok', 'info {C}/good.pcd')
    case('e57', 'ok', 'info {C}/good.e57')

    # ---- PLY
    ply_points = ''.join(f'{0.1 * i} 5 0 {i % 4} {i // 4}\n' for i in range(24))
    def ply(count, body, extra_header='', fmt='ascii'):
        return (f'ply\nformat {fmt} 1.0\ncomment lidarshop_scan 0 4 6 ' + ' '.join(IDENTITY.split()) + '\n'
                f'{extra_header}element vertex {count}\nproperty float x\nproperty float y\nproperty float z\n'
                'property int row\nproperty int col\nend_header\n' + body)
    case('ply', 'ok', 'info ' + write('grid_ok.ply', ply(24, ply_points)))
    case('ply', 'error', 'info ' + write('rows_2p28.ply', ply(1, '0 5 0 3 5\n').replace('lidarshop_scan 0 4 6', 'lidarshop_scan 0 268435456 1')))
    case('ply', 'error', 'info ' + write('grid_16384sq.ply', ply(1, '0 5 0 3 5\n').replace('lidarshop_scan 0 4 6', 'lidarshop_scan 0 16384 16384')))
    case('ply', 'error', 'info ' + write('count_2p28.ply', ply(268435456, ply_points)))
    case('ply', 'error', 'info ' + write('count_zero.ply', ply(0, ply_points)))
    case('ply', 'error', 'info ' + write('count_short.ply', ply(10, ply_points)))
    case('ply', 'error', 'info ' + write('count_long.ply', ply(30, ply_points)))
    case('ply', 'error', 'info ' + write('count_negative.ply', ply(-1, ply_points)))
    case('ply', 'error', 'info ' + write('duplicate_cell.ply', ply(24, ply_points.replace('0.1 5 0 1 0', '0.1 5 0 0 0'))))
    case('ply', 'error', 'info ' + write('cell_outside.ply', ply(24, ply_points.replace('0.1 5 0 1 0', '0.1 5 0 9 0'))))
    case('ply', 'error', 'info ' + write('point_1e38.ply', ply(24, ply_points.replace('0.1 5 0 1 0', '1e38 5 0 1 0'))))
    case('ply', 'error', 'info ' + write('pose_shear.ply', ply(24, ply_points).replace(' '.join(IDENTITY.split()), '1 0.5 0 0 0 1 0 0 0 0 1 0 0 0 0 1')))
    case('ply', 'error', 'info ' + write('pose_1e308.ply', ply(24, ply_points).replace(' '.join(IDENTITY.split()), '1 0 0 1e308 0 1 0 0 0 0 1 0 0 0 0 1')))
    case('ply', 'error', 'info ' + write('binary_short.ply', ply(24, '', fmt='binary_little_endian').encode() + b'\0' * 40))
    case('ply', 'error', 'info ' + write('binary_long.ply', ply(1, '', fmt='binary_little_endian').encode() + b'\0' * 400))
    case('ply', 'error', 'info ' + write('list_huge.ply', 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 1\n255 0 0 0\n'))
    case('ply', 'error', 'info ' + write('no_end_header.ply', 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n'))
    case('ply', 'error', 'info ' + write('bad_format.ply', 'ply\nformat utf16 1.0\nend_header\n'))
    good_ply = open(os.path.join(CORPUS, 'good.ply'), 'rb').read()
    for cut in [3, 20, len(good_ply) // 2, len(good_ply) - 3]:
        case('ply', 'error', 'info ' + write(f'truncated_{cut}.ply', good_ply[:cut]))
    flips('ply', good_ply, 10, rnd)
    case('ply', 'error', 'info {FIFO}.ply')

    # ---- PCD
    def pcd(width, height, points, data='ascii', body=None, fields='x y z', viewpoint='0 0 0 1 0 0 0'):
        n = len(fields.split())
        header = (f'# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {" ".join(["4"] * n)}\nTYPE {" ".join(["F"] * n)}\n'
                  f'COUNT {" ".join(["1"] * n)}\nWIDTH {width}\nHEIGHT {height}\nVIEWPOINT {viewpoint}\nPOINTS {points}\nDATA {data}\n')
        return header + (body if body is not None else ''.join(f'{0.1 * i} 0 5\n' for i in range(points if points < 100 else 6)))
    case('pcd', 'ok', 'info ' + write('ascii_ok.pcd', pcd(6, 1, 6)))
    case('pcd', 'error', 'info ' + write('ascii_16gb.pcd', pcd(65536, 16384, 65536 * 16384)))
    case('pcd', 'error', 'info ' + write('ascii_2p28.pcd', pcd(268435456, 1, 268435456)))
    case('pcd', 'error', 'info ' + write('count_zero.pcd', pcd(0, 1, 0, body='0 0 5\n')))
    case('pcd', 'error', 'info ' + write('points_disagree.pcd', pcd(6, 1, 5)))
    case('pcd', 'error', 'info ' + write('more_lines.pcd', pcd(6, 1, 6, body=''.join(f'{0.1 * i} 0 5\n' for i in range(9)))))
    case('pcd', 'error', 'info ' + write('fewer_lines.pcd', pcd(6, 1, 6, body='0 0 5\n')))
    case('pcd', 'error', 'info ' + write('point_1e38.pcd', pcd(6, 1, 6, body='1e38 0 5\n' + ''.join(f'{0.1 * i} 0 5\n' for i in range(5)))))
    case('pcd', 'error', 'info ' + write('viewpoint_shear.pcd', pcd(6, 1, 6, viewpoint='0 0 0 0 0 0 0')))
    case('pcd', 'error', 'info ' + write('viewpoint_1e308.pcd', pcd(6, 1, 6, viewpoint='1e308 0 0 1 0 0 0')))
    case('pcd', 'error', 'info ' + write('binary_short.pcd', pcd(1000, 1000, 1000000, data='binary', body='').encode() + b'\0' * 100))
    case('pcd', 'error', 'info ' + write('compressed_huge.pcd', pcd(100000, 1000, 100000000, data='binary_compressed', body='').encode() + struct.pack('<II', 20, 0xFFFFFFF0) + b'\0' * 20))
    case('pcd', 'error', 'info ' + write('bad_size.pcd', pcd(6, 1, 6).replace('SIZE 4 4 4', 'SIZE 3 4 4')))
    case('pcd', 'error', 'info ' + write('int_1e30.pcd', pcd(6, 1, 6, fields='x y z label', body='0 0 5 1e30\n' * 6).replace('TYPE F F F F', 'TYPE F F F I')))
    good_pcd = open(os.path.join(CORPUS, 'good.pcd'), 'rb').read()
    for cut in [5, len(good_pcd) // 2, len(good_pcd) - 4]:
        case('pcd', 'error', 'info ' + write(f'truncated_{cut}.pcd', good_pcd[:cut]))
    flips('pcd', good_pcd, 8, rnd)
    case('pcd', 'error', 'info {FIFO}.pcd')

    # ---- E57: edit the XML of a lidarshop-written file, recompute the page CRCs
    good_e57 = open(os.path.join(CORPUS, 'good.e57'), 'rb').read()
    logical = e57_logical(good_e57)
    def e57_edit(name, old, new):
        # The same XML length keeps every offset: pad or squeeze the indentation after the edit.
        assert old in logical, old
        at = logical.index(old)
        edited = logical[:at] + new + logical[at + len(old):]
        delta = len(new) - len(old)
        while delta > 0:
            gap = edited.index(b'\n  ', at + len(new))
            edited = edited[:gap + 1] + edited[gap + 2:]
            delta -= 1
        if delta < 0:
            gap = edited.index(b'\n', at + len(new))
            edited = edited[:gap + 1] + b' ' * -delta + edited[gap + 1:]
        assert len(edited) == len(logical)
        case('e57', 'error', 'info ' + write(name, e57_pages(edited)))
    e57_edit('rows_2p28.e57', b'<rowMaximum type="Integer">3<', b'<rowMaximum type="Integer">268435455<')
    e57_edit('grid_4x1e8.e57', b'<columnMaximum type="Integer">5<', b'<columnMaximum type="Integer">99999999<')
    e57_edit('rows_negative.e57', b'<rowMaximum type="Integer">3<', b'<rowMaximum type="Integer">-7<')
    e57_edit('records_2p28.e57', b'recordCount="24"', b'recordCount="268435456"')
    e57_edit('records_zero.e57', b'recordCount="24"', b'recordCount="0"')
    e57_edit('records_short.e57', b'recordCount="24"', b'recordCount="10"')
    e57_edit('translation_1e308.e57', b'<translation type="Structure">', b'<translation type="Structure"><x type="Float">1e308</x>')
    for cut in [0, 48, 1024, len(good_e57) // 2, len(good_e57) - 4]:
        case('e57', 'error', 'info ' + write(f'truncated_{cut}.e57', good_e57[:cut]))
    for i in range(10):
        lg = bytearray(logical)
        for _ in range(rnd.randint(1, 4)):
            lg[rnd.randrange(len(lg))] = rnd.randrange(256)
        case('e57', 'any', 'info ' + write(f'flip_{i}.e57', e57_pages(bytes(lg))))
    case('e57', 'error', 'info ' + write('bad_crc.e57', good_e57[:100] + bytes([good_e57[100] ^ 1]) + good_e57[101:]))
    case('e57', 'error', 'info {FIFO}.e57')
    for name in ['corrupt_crc.e57', 'empty.e57', 'read_error.e57', 'cartesian_invalid_state_single.e57']:
        case('e57', 'any', 'info {S}/e57/' + name)

    # ---- OBJ (through a scene) and MTL
    scene_base = {'scanner': {'position': [0, 0, 1], 'columns': 40, 'rows': 20, 'max_range': 50},
                  'objects': [{'primitive': 'plane', 'size': [20, 20], 'translate': [0, 10, 0]}]}
    def scene(name, objects=None, scanner=None, raw=None):
        s = json.loads(json.dumps(scene_base))
        if objects is not None: s['objects'] = objects
        if scanner is not None: s['scanner'].update(scanner)
        return write(name, raw if raw is not None else json.dumps(s))
    def scan_case(reader, expect, path, extra=''):
        case(reader, expect, f'scan {path} -o {{W}}/out.ptx -q {extra}'.strip())
    scan_case('scene', 'ok', scene('scene_ok.json'))
    obj = 'v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n'
    write('tri.obj', obj)
    scan_case('obj', 'ok', scene('obj_ok.json', [{'mesh': 'tri.obj', 'translate': [0, 5, 0]}]))
    for name, body in {'vertex_1e38': 'v 1e38 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n',
                       'vertex_nan': 'v nan 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n',
                       'face_outside': 'v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 9\n',
                       'face_zero': 'v 0 0 0\nv 1 0 0\nv 0 0 1\nf 0 1 2\n',
                       'face_negative_huge': 'v 0 0 0\nv 1 0 0\nv 0 0 1\nf -99999999999 1 2\n',
                       'no_faces': 'v 0 0 0\n',
                       'garbage': '\x00\xff\x13 f v vt\n' * 20}.items():
        write(f'{name}.obj', body)
        scan_case('obj', 'error', scene(f'obj_{name}.json', [{'mesh': f'{name}.obj', 'translate': [0, 5, 0]}]))
    write('mtl_fifo.obj', 'mtllib fifo.mtl\n' + obj)
    scan_case('obj', 'ok', scene('obj_mtl_fifo.json', [{'mesh': 'mtl_fifo.obj', 'translate': [0, 5, 0]}]))
    write('huge_texture.mtl', 'newmtl m\nmap_Kd huge.png\n')
    # a 1 x 1 PNG whose header claims 100000 x 100000 pixels (CRC of IHDR recomputed)
    ihdr = struct.pack('>IIBBBBB', 100000, 100000, 8, 2, 0, 0, 0)
    png = b'\x89PNG\r\n\x1a\n' + struct.pack('>I', 13) + b'IHDR' + ihdr + struct.pack('>I', zlib.crc32(b'IHDR' + ihdr))
    idat = zlib.compress(b'\0' * 100)
    png += struct.pack('>I', len(idat)) + b'IDAT' + idat + struct.pack('>I', zlib.crc32(b'IDAT' + idat)) + b'\0\0\0\0IEND\xaeB`\x82'
    write('huge.png', png)
    write('huge_texture.obj', 'mtllib huge_texture.mtl\nv 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n')
    scan_case('obj', 'ok', scene('obj_huge_texture.json', [{'mesh': 'huge_texture.obj', 'translate': [0, 5, 0]}]))
    scan_case('obj', 'error', scene('obj_fifo.json', [{'mesh': 'fifo.obj'}]))

    # ---- scenes
    scan_case('scene', 'error', scene('scanner_1e308.json', scanner={'position': [1e308, 0, 0]}))
    scan_case('scene', 'error', scene('object_1e308.json', [{'primitive': 'box', 'translate': [1e308, 0, 0]}]))
    scan_case('scene', 'error', scene('object_1e30.json', [{'primitive': 'box', 'translate': [1e30, 0, 0]}]))
    scan_case('scene', 'error', scene('scale_1e300.json', [{'primitive': 'box', 'scale': 1e300}]))
    scan_case('scene', 'error', scene('radius_1e300.json', [{'primitive': 'sphere', 'radius': 1e300}]))
    scan_case('scene', 'error', scene('matrix_1e308.json', [{'primitive': 'box', 'matrix': [[1, 0, 0, 1e308], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}]))
    scan_case('scene', 'error', scene('spheres_4096.json', [{'primitive': 'sphere', 'segments': 4096}] * 64))
    scan_case('scene', 'error', scene('spheres_many.json', [{'primitive': 'sphere', 'translate': [i % 64, 10 + i // 64, 0]} for i in range(2048)]))
    scan_case('scene', 'ok', scene('car_sub5.json', [{'primitive': 'car', 'subdivisions': 5, 'translate': [0, 8, 0]}]))
    # 14 M triangles: past the 8 M a scene may hold (10 s, 2.4 GB in a release build)
    scene('cars_sub7.json', [{'primitive': 'car', 'subdivisions': 7}])
    scan_case('scene', 'error', '{C}/cars_sub7.json')
    scan_case('scene', 'error', '{C}/car_sub5.json', '--max-memory 1M')
    scan_case('scene', 'error', scene('cars_sub6_many.json', [{'primitive': 'car', 'subdivisions': 6, 'translate': [i * 5, 10, 0]} for i in range(16)]))
    scan_case('scene', 'error', scene('facades_many.json', [{'primitive': 'facade', 'floors': 100, 'windows_per_floor': 200, 'translate': [0, 10 + i, 0]} for i in range(64)]))
    scan_case('scene', 'error', scene('grid_huge.json', scanner={'columns': 100000, 'rows': 2684}))
    scan_case('scene', 'error', scene('max_range_1e308.json', scanner={'max_range': 1e308}))
    scan_case('scene', 'error', scene('not_json.json', raw='{"scanner": '))
    scan_case('scene', 'error', scene('deep.json', raw='[' * 20000 + ']' * 20000))
    scan_case('scene', 'error', scene('unknown_key.json', [{'primitive': 'box', 'bogus': 1}]))
    scan_case('scene', 'error', scene('number_overflow.json', raw='{"objects": [{"primitive": "box", "translate": [1e+315, 0, 0]}]}'))
    scan_case('scene', 'error', '{FIFO}.json')
    scan_case('scene', 'error', '{C}/folder.ptx')

    # ---- strokes (segment) and masks (fill)
    base_scan = '{C}/good.ptx'
    def seg(expect, strokes):
        case('strokes', expect, f'segment {base_scan} --strokes {strokes} -o {{W}}/mask.png -q')
    stroke = lambda label, points: {'label': label, 'points': points}
    seg('ok', write('strokes_ok.json', json.dumps({'strokes': [stroke('object', [[1, 1], [2, 1]]), stroke('background', [[5, 3], [5, 0]])]})))
    bg = stroke('background', [[5, 3], [5, 0]])
    for name, body in {'not_json': '{', 'huge_width': json.dumps({'strokes': [dict(stroke('object', [[1, 1]]), width=1e9), bg]}),
                       'width_300': json.dumps({'strokes': [dict(stroke('object', [[1, 1]]), width=300), bg]}),
                       'nan': '{"strokes": [{"label": "object", "points": [[NaN, 1]]}]}',
                       'far': json.dumps({'strokes': [stroke('object', [[1e300, 1], [2, -1e300]]), bg]}),
                       'outside': json.dumps({'strokes': [stroke('object', [[100, 1]]), bg]}),
                       'many': json.dumps({'strokes': [stroke('object', [[i % 6, i % 4] for i in range(5000)]), bg]}),
                       'no_points': json.dumps({'strokes': [stroke('object', []), bg]}),
                       'bad_label': json.dumps({'strokes': [stroke('sky', [[1, 1]]), bg]}),
                       'wrong_type': json.dumps({'strokes': 'x'})}.items():
        seg('any' if name == 'many' else 'error', write(f'strokes_{name}.json', body))
    seg('error', '{FIFO}.json')
    seg('error', write('strokes_number_overflow.json', '{"strokes": [{"label": "object", "points": [[1e+316, 1]]}]}'))
    seg('error', write('strokes_wrong_size.png', png[:0] or open(os.path.join(CORPUS, 'huge.png'), 'rb').read()))

    def fill(expect, mask):
        case('mask', expect, f'fill {base_scan} --mask {mask} -o {{W}}/filled.ptx -q')
    fill('error', '{C}/huge.png')
    fill('error', write('mask_garbage.png', bytes(rnd.randrange(256) for _ in range(300))))
    fill('error', write('mask_truncated.png', png[:40]))
    fill('error', '{FIFO}.png')
    # a DICOM preamble: OpenCV would hand it to gdcm, which aborts on malformed input (found by mask_fuzz)
    fill('error', write('mask_dicom.png', b'\0' * 128 + b'DICM' + b'\0' * 64))
    fill('error', '{C}/folder.ptx')

    # ---- pose files and --pose text (verify)
    def verify(expect, pose, extra=''):
        case('pose', expect, f'verify --scan {base_scan} --model builtin:sedan --pose {pose} --samples 2000 -q {extra}'.strip())
    verify('ok', '0,5,0,0')
    verify('ok', write('pose_ok.txt', '1 0 0 0\n0 1 0 5\n0 0 1 0\n0 0 0 1\n'))
    verify('ok', write('pose_scaled.txt', '2 0 0 0\n0 2 0 5\n0 0 2 0\n0 0 0 1\n'))
    for name, body in {'zero': '0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1\n', 'shear': '1 0.5 0 0\n0 1 0 5\n0 0 1 0\n0 0 0 1\n',
                       'mirror': '-1 0 0 0\n0 1 0 5\n0 0 1 0\n0 0 0 1\n', 'scale_axis': '1 0 0 0\n0 2 0 5\n0 0 1 0\n0 0 0 1\n',
                       't1e308': '1 0 0 1e308\n0 1 0 5\n0 0 1 0\n0 0 0 1\n', 'nan': '1 0 0 nan\n0 1 0 5\n0 0 1 0\n0 0 0 1\n',
                       'short': '1 0 0\n', 'words': 'one two\n', 'huge_scale': '1e7 0 0 0\n0 1e7 0 5\n0 0 1e7 0\n0 0 0 1\n'}.items():
        verify('error', write(f'pose_{name}.txt', body))
    verify('error', '1e308,0,0,0')
    verify('error', '0,5,0,inf')
    verify('error', '{FIFO}.txt')
    verify('error', ','.join(['1'] * 200))  # 400 characters: "file name too long" must not escape (pose_fuzz)

    # ---- LAS (point format 6, LAS 1.4) and XYZ / PTS
    def las(count=24, claimed=None, record_length=30, offset_to_points=375, scale=0.001, fmt=6, minor=4, vlrs=0):
        header = bytearray(375)
        header[0:4] = b'LASF'
        header[24], header[25] = 1, minor
        struct.pack_into('<HIIBH', header, 94, 375, offset_to_points, vlrs, fmt, record_length)
        struct.pack_into('<ddd', header, 131, scale, scale, scale)
        struct.pack_into('<Q', header, 247, count if claimed is None else claimed)
        body = b''.join(struct.pack('<iiiHBBBBhHd', 100 * i - 300, 5000, 10 * i, 1000 * i, 0x11, 0, 0, 0, 0, 0, 0)
                        for i in range(count))
        return bytes(header) + body
    good_las = las()
    case('las', 'ok', 'info ' + write('good.las', good_las))
    case('las', 'error', 'info ' + write('count_2p40.las', las(claimed=1 << 40)))
    case('las', 'error', 'info ' + write('count_short.las', las(claimed=30)))
    case('las', 'ok', 'info ' + write('count_zero.las', las(claimed=0)))  # a header that promises no point
    case('las', 'error', 'info ' + write('offset_past_end.las', las(offset_to_points=1 << 20)))
    case('las', 'error', 'info ' + write('offset_in_header.las', las(offset_to_points=100)))
    case('las', 'error', 'info ' + write('record_too_short.las', las(record_length=20)))
    # Miscounted records are read as far as they fit, with a warning (PDAL's bad_vlr_count.las).
    case('las', 'ok', 'info ' + write('vlrs_past_points.las', las(vlrs=1000)))
    case('las', 'error', 'info ' + write('scale_subnormal.las', las(scale=5e-324)))
    case('las', 'error', 'info ' + write('scale_zero.las', las(scale=0.0)))
    case('las', 'error', 'info ' + write('scale_huge.las', las(scale=1e6)))
    case('las', 'error', 'info ' + write('format_11.las', las(fmt=11)))
    case('las', 'error', 'info ' + write('laz_bits.las', las(fmt=6 | 0x80)))
    case('las', 'error', 'info ' + write('version_1_9.las', las(minor=9)))
    for cut in [0, 3, 100, 374, len(good_las) - 7]:
        case('las', 'error', 'info ' + write(f'truncated_{cut}.las', good_las[:cut]))
    las_random = random.Random(16)
    flips('las', good_las, 10, las_random)
    case('las', 'error', 'info ' + write('garbage.las', bytes(las_random.randrange(256) for _ in range(600))))
    case('las', 'ok', 'info ' + write('uncompressed.laz', good_las))  # .laz is read as LAS, compressed or not
    case('las', 'error', 'info {FIFO}.las')
    xyz_points = ''.join(f'{0.1 * i} 5 {0.05 * i} 0.5 10 20 30\n' for i in range(24))
    case('xyz', 'ok', 'info ' + write('good.xyz', xyz_points))
    case('xyz', 'ok', 'info ' + write('good.pts', '24\n' + xyz_points))
    # A PTS count that disagrees with the lines is read with a warning (every point line is a point).
    case('xyz', 'ok', 'info ' + write('count_huge.pts', '100000000000\n' + xyz_points))
    case('xyz', 'ok', 'info ' + write('count_short.pts', '30\n' + xyz_points))
    case('xyz', 'error', 'info ' + write('columns_5.xyz', '1 2 3 4 5\n'))
    case('xyz', 'error', 'info ' + write('columns_differ.xyz', xyz_points + '1 2 3\n'))
    case('xyz', 'error', 'info ' + write('point_1e38.xyz', xyz_points.replace('0.0 5', '1e38 5', 1)))
    case('xyz', 'error', 'info ' + write('color_300.xyz', xyz_points.replace('10 20 30', '10 20 300', 1)))
    case('xyz', 'error', 'info ' + write('garbage.xyz', bytes(las_random.randrange(256) for _ in range(400))))
    flips('xyz', xyz_points.encode(), 6, las_random)
    case('xyz', 'error', 'info {FIFO}.xyz')

    # ---- issue 37: what the budget must count (each case with a memory limit: its budget + 200 MB)
    # E57 fields that take no bits: 2^24 records in 3 KB; 8 scans of 2^22 records each.
    case('budget', 'error', 'convert ' + write('e57_zero_bits.e57', e57_build([(b'zero', 1 << 24, CONSTANT_POINT)])) + ' {W}/o.ply --max-memory 256M -q')
    case('budget', 'error', 'convert ' + write('e57_zero_bits_8.e57', e57_build([(b'zero', 1 << 22, CONSTANT_POINT)] * 8)) + ' {W}/o.ply --max-memory 1G -q')
    # PLY: 20 lidarshop_scan comments of 2048 x 2048 cells, each within the limit, together 2.4 GB.
    many = ply(1, '0 5 0 3 5\n').replace('comment lidarshop_scan 0 4 6 ' + ' '.join(IDENTITY.split()) + '\n',
                                         ''.join(f'comment lidarshop_scan {i} 2048 2048 ' + ' '.join(IDENTITY.split()) + '\n' for i in range(20)))
    case('budget', 'error', 'convert ' + write('ply_scans_20x2048sq.ply', many) + ' {W}/o.ply --max-memory 512M -q')
    # Images: a 20000 x 20000 1-bit PNG of 50 KB decodes to 400 MB grey, 1.2 GB RGB; a 4000 x 4000 one of 2 KB
    # to 48 MB RGB. The size is in the header: refused (or compared with the scan's) before decoding.
    huge_png = png_image(20000, 20000)
    write('png_20000sq.png', huge_png)
    fill('error', '{C}/png_20000sq.png --max-memory 64M')
    seg('error', '{C}/png_20000sq.png --max-memory 64M')
    case('budget', 'error', 'inpaint {C}/good_render.png --mask {C}/png_20000sq.png -o {W}/i.png --max-memory 64M')
    subprocess.run([lidarshop, 'render', os.path.join(CORPUS, 'good.ptx'), '-o', os.path.join(CORPUS, 'good_render.png')], check=True)
    write('texture_20000sq.mtl', 'newmtl m\nmap_Kd png_20000sq.png\n')
    write('texture_20000sq.obj', 'mtllib texture_20000sq.mtl\nv 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n')
    scan_case('budget', 'ok', scene('obj_texture_20000sq.json', [{'mesh': 'texture_20000sq.obj', 'translate': [0, 5, 0]}]), '--max-memory 256M')
    small_scan = [(b'photos', 24, CONSTANT_POINT)]
    e57_photo = write('e57_photo_20000sq.e57', e57_build(small_scan, [(b'big', 0)], [huge_png]))
    case('budget', 'any', f'convert {e57_photo} {{W}}/o.e57 --max-memory 512M -q')
    e57_photos = write('e57_photo_4000sq_x200.e57', e57_build(small_scan, [(b'p%d' % i, 0) for i in range(200)], [png_image(4000, 4000)]))
    case('budget', 'any', f'convert {e57_photos} {{W}}/o.e57 --max-memory 512M -q')
    case('budget', 'any@1000M', f'info {e57_photos}')
    # A Latin-1 scan name: E57 XML is UTF-8.
    latin1 = write('e57_latin1_name.e57', e57_build([(b'caf\xe9', 24, CONSTANT_POINT)]))
    case('e57', 'error', f'info {latin1}')
    case('e57', 'error', f'convert {latin1} {{W}}/o.e57 -q')
    # The image libraries' own lines: a PNG whose compressed data is broken, a JPEG cut short.
    subprocess.run([lidarshop, 'render', os.path.join(CORPUS, 'good.ptx'), '--channel', 'valid', '-o', os.path.join(CORPUS, 'good_valid.png')], check=True)
    broken = bytearray(open(os.path.join(CORPUS, 'good_valid.png'), 'rb').read())
    at = broken.index(b'IDAT') + 8
    broken[at:at + 6] = b'\xff' * 6
    fill('error', write('mask_bad_idat.png', bytes(broken)))
    subprocess.run([lidarshop, 'render', os.path.join(CORPUS, 'good.ptx'), '--channel', 'valid', '-o', os.path.join(CORPUS, 'good_valid.jpg')], check=True)
    jpeg = bytearray(open(os.path.join(CORPUS, 'good_valid.jpg'), 'rb').read())
    os.remove(os.path.join(CORPUS, 'good_valid.jpg'))
    at = jpeg.index(b'\xff\xda')
    jpeg[at + 20:at + 24] = b'\xff\xd0\xff\xd5'  # restart markers out of order: libjpeg warns, then decodes
    fill('any', write('mask_corrupt_data.jpg', bytes(jpeg[:-10]) + b'\xff\xd9'))
    # Amplification: a PCD claiming 1.2 GB of LZF data in 172 bytes; 100,000 one-point PTX scans in 7 MB.
    case('budget', 'error@300M', 'info ' + write('lzf_1g.pcd', pcd(100000000, 1, 100000000, data='binary_compressed', body='').encode()
                                                          + struct.pack('<II', 20, 1200000000) + b'\0' * 20))
    case('budget', 'error@400M', 'info {B}/scans_100k.ptx')
    scan_case('budget', 'error', '{B}/boxes_20k.json', '--max-memory 256M')

    # ---- options (the options layer: Check() of each command's options)
    L = base_scan
    for args in [f'render {L} -o {{W}}/r.png --min inf',
                 f'render {L} -o {{W}}/r.png --min 1e308', f'render {L} -o {{W}}/r.png --min 5 --max 1',
                 f'verify --scan {L} --model builtin:sedan --pose 0,5,0,0 --sigma 1e308 -q',
                 f'verify --scan {L} --model builtin:sedan --pose 0,5,0,0 --sigma -1 -q',
                 f'verify --scan {L} --model builtin:sedan --pose 0,5,0,0 --allowance inf -q',
                 f'verify --scan {L} --model builtin:sedan --pose 0,5,0,0 --samples 2000000000 -q',
                 f'verify --scan {L} --model builtin:sedan --pose 0,5,0,0 --samples -5 -q',
                 f'verify --scan {L} --model builtin:sedan --pose 0,5,0,0 --seed -1 -q',
                 f'verify --scan {L} --model builtin:sedan --pose 0,5,0,0 --seed 99999999999999999999 -q',
                 f'sweep --scan {L} --model builtin:sedan --yaws 0:1e9:1e-9 --out {{W}}/sweep -q',
                 f'sweep --scan {L} --model builtin:sedan --yaws 1e300:inf:1 --out {{W}}/sweep -q',
                 f'sweep --scan {L} --model builtin:sedan --x-range -1e9:1e9 --out {{W}}/sweep -q',
                 f'sweep --scan {L} --model builtin:sedan --x-range 0:1 --y-range 0:1 --step 1e-9 --out {{W}}/sweep -q',
                 f'fill {L} --mask {{C}}/huge.png -o {{W}}/f.ptx --seed -3 -q',
                 f'info {L} --max-memory 0', f'convert {L} {{W}}/c.ply --max-memory abc',
                 f'scan {{C}}/scene_ok.json -o {{W}}/s.ptx --rows 100000 --columns 100000 -q',
                 f'scan {{C}}/scene_ok.json -o {{W}}/s.ptx --rows -5 -q', f'scan {{C}}/scene_ok.json -o {{W}}/s.ptx --threads -1 -q',
                 f'render {L} -o {{W}}/r.png --orbit 30 --width 1000000 --height 1000000',
                 f'render {L} -o {{W}}/r.png --eye 0,0,0 --target 0,0,0']:
        case('options', 'error', args)
    case('options', 'ok', f'convert {L} {{W}}/c.ply --max-memory 2G -q')
    case('options', 'ok', f'convert {L} {{W}}/c.ply --max-memory 1M -q')
    case('options', 'ok', f'render {L} -o {{W}}/r.png --min nan --max 1')

    # ---- data safety: an output equal to an input or to another output
    for args in ['convert {W}/copy.ptx {W}/copy.ptx', 'render {W}/copy.ptx -o {W}/copy.ptx',
                 'fill {W}/copy.ptx --mask {W}/mask.png -o {W}/copy.ptx -q',
                 'inpaint {W}/img.png --mask {W}/mask.png -o {W}/img.png',
                 'poisson fill {W}/img.png --mask {W}/mask.png -o {W}/img.png',
                 'verify --scan {W}/copy.ptx --model builtin:sedan --pose 0,5,0,0 --json {W}/copy.ptx -q',
                 'scan {C}/scene_ok.json -o {W}/a.ply --mesh {W}/a.ply -q',
                 'segment {W}/copy.ptx --strokes {C}/strokes_ok.json -o {W}/copy.ptx -q']:
        case('safety', 'error', args)

    with open(os.path.join(HERE, 'cases.txt'), 'w') as f:
        f.write('# reader|expect|arguments of lidarshop (written by make_corpus.py; expect any = a clean error or success)\n')
        f.write('\n'.join(cases) + '\n')
    print(f'{len(cases)} cases')


if __name__ == '__main__':
    main()
