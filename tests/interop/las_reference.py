"""An independent LAS reader for the interop test, written from ASPRS LAS 1.4 R15 (not lidarshop's reader).

read_las(path) -> dict with the header fields, the VLR list and numpy arrays of every standard attribute.
Only uncompressed LAS; it raises ValueError on anything it does not understand.
"""
import struct

import numpy as np

# Point data record formats 0-10: size and the byte offsets of their fields (table 7-16 of the specification).
RECORD_SIZE = {0: 20, 1: 28, 2: 26, 3: 34, 4: 57, 5: 63, 6: 30, 7: 36, 8: 38, 9: 59, 10: 67}
GPS_OFFSET = {1: 20, 3: 20, 4: 20, 5: 20, 6: 22, 7: 22, 8: 22, 9: 22, 10: 22}
RGB_OFFSET = {2: 20, 3: 28, 5: 28, 7: 30, 8: 30, 10: 30}
NIR_OFFSET = {8: 36, 10: 36}


def read_las(path):
    data = open(path, "rb").read()
    if data[:4] != b"LASF":
        raise ValueError("not LASF")
    major, minor = data[24], data[25]
    header_size, offset_to_points, vlr_count = struct.unpack_from("<HII", data, 94)
    point_format_byte, record_length, legacy_count = struct.unpack_from("<BHI", data, 104)
    if point_format_byte & 0xC0:
        raise ValueError("compressed")
    fmt = point_format_byte & 0x3F
    scale = struct.unpack_from("<3d", data, 131)
    offset = struct.unpack_from("<3d", data, 155)
    bounds = struct.unpack_from("<6d", data, 179)  # max x, min x, max y, min y, max z, min z
    count = legacy_count
    if minor >= 4 and header_size >= 375:
        count64 = struct.unpack_from("<Q", data, 247)[0]
        if count64:
            count = count64
    vlrs = []
    pos = header_size
    for _ in range(vlr_count):
        if pos + 54 > offset_to_points:
            break
        user = data[pos + 2:pos + 18].split(b"\0")[0].decode("latin-1")
        record_id, length = struct.unpack_from("<HH", data, pos + 18)
        vlrs.append((user, record_id, data[pos + 54:pos + 54 + length]))
        pos += 54 + length
    n_available = (len(data) - offset_to_points) // record_length if record_length else 0
    if count > n_available:
        raise ValueError(f"truncated: {count} points promised, {n_available} in the file")
    raw = np.frombuffer(data, dtype=np.uint8, count=count * record_length, offset=offset_to_points)
    raw = raw.reshape(count, record_length)

    def field(off, dtype):
        size = np.dtype(dtype).itemsize
        return raw[:, off:off + size].copy().view(dtype).reshape(count)

    xyz_int = np.stack([field(4 * a, "<i4") for a in range(3)], axis=1)
    xyz = xyz_int * np.array(scale) + np.array(offset)
    out = {
        "version": (major, minor), "format": fmt, "record_length": record_length, "count": count,
        "scale": scale, "offset": offset, "bounds": bounds, "vlrs": vlrs, "xyz_int": xyz_int, "xyz": xyz,
        "intensity": field(12, "<u2"),
    }
    legacy = fmt <= 5
    if legacy:
        b = field(14, "u1")
        out["return_number"] = b & 7
        out["number_of_returns"] = (b >> 3) & 7
        out["scan_direction_flag"] = (b >> 6) & 1
        out["edge_of_flight_line"] = (b >> 7) & 1
        c = field(15, "u1")
        out["classification"] = c & 31
        out["synthetic"] = (c >> 5) & 1
        out["key_point"] = (c >> 6) & 1
        out["withheld"] = (c >> 7) & 1
        out["overlap"] = np.zeros(count, np.uint8)
        out["scan_angle_deg"] = field(16, "i1").astype(np.float64)
        out["user_data"] = field(17, "u1")
        out["point_source_id"] = field(18, "<u2")
    else:
        b = field(14, "u1")
        out["return_number"] = b & 15
        out["number_of_returns"] = b >> 4
        f = field(15, "u1")
        out["synthetic"] = f & 1
        out["key_point"] = (f >> 1) & 1
        out["withheld"] = (f >> 2) & 1
        out["overlap"] = (f >> 3) & 1
        out["scanner_channel"] = (f >> 4) & 3
        out["scan_direction_flag"] = (f >> 6) & 1
        out["edge_of_flight_line"] = (f >> 7) & 1
        out["classification"] = field(16, "u1")
        out["user_data"] = field(17, "u1")
        out["scan_angle_deg"] = field(18, "<i2").astype(np.float64) * 0.006
        out["point_source_id"] = field(20, "<u2")
    if fmt in GPS_OFFSET:
        out["gps_time"] = field(GPS_OFFSET[fmt], "<f8")
    if fmt in RGB_OFFSET:
        out["rgb"] = np.stack([field(RGB_OFFSET[fmt] + 2 * c, "<u2") for c in range(3)], axis=1)
    if fmt in NIR_OFFSET:
        out["nir"] = field(NIR_OFFSET[fmt], "<u2")
    extra = record_length - RECORD_SIZE[fmt]
    out["extra_bytes"] = raw[:, RECORD_SIZE[fmt]:].copy() if extra > 0 else None
    return out


if __name__ == "__main__":
    import sys
    for p in sys.argv[1:]:
        try:
            r = read_las(p)
            print(f"{p.split('/')[-1]:40s} 1.{r['version'][1]} fmt {r['format']} len {r['record_length']} n {r['count']} vlrs {[(u, i, len(d)) for u, i, d in r['vlrs']]}")
        except Exception as e:
            print(f"{p.split('/')[-1]:40s} ERROR {e}")
