"""An independent E57 (ASTM E2807) decoder for tests: written from the format description, shares no code with
lidarshop's reader (src/lidarshop/io/e57*.cc), so a test can check what lidarshop writes and reads against it.

The format, as used here:
- The file is 1024-byte physical pages; each holds 1020 payload bytes and the CRC-32C (Castagnoli) of them,
  big-endian. The payloads, concatenated, are the logical stream; offsets in the header and the XML are
  physical, lengths logical.
- Header (48 bytes): "ASTM-E57", versionMajor u32, versionMinor u32, filePhysicalLength u64,
  xmlPhysicalOffset u64, xmlLogicalLength u64, pageSize u64 (all little-endian).
- The XML section: e57Root with data3D (scans) and images2D (photos). A scan's `points` is a
  CompressedVector (fileOffset, recordCount) whose `prototype` lists the fields; its binary section starts
  with sectionId 1, 7 reserved bytes, sectionLogicalLength u64, dataPhysicalOffset u64, indexPhysicalOffset
  u64; then packets: packetType u8 (0 index, 1 data, 2 empty), flags u8, packetLogicalLengthMinus1 u16; a
  data packet then has bytestreamCount u16 and one u16 buffer length per bytestream, then the buffers. Each
  field's bytestream is its buffers concatenated over the packets; Float fields are IEEE little-endian
  (single or double), Integer / ScaledInteger fields are bit-packed LSB first with
  ceil(log2(maximum - minimum + 1)) bits per value holding value - minimum (ScaledInteger: value * scale +
  offset).
- A Blob (jpegImage / pngImage of an images2D entry) is a section with sectionId 0, 7 reserved bytes,
  sectionLogicalLength u64, then the bytes.

decode(path) returns an E57 object or raises E57Error naming what is wrong. Uses numpy only.
"""

import math
import struct
import xml.etree.ElementTree as ET

import numpy as np

E57_NS = "http://www.astm.org/COMMIT/E57/2010-e57-v1.0"
PAGE = 1024
PAYLOAD = 1020


class E57Error(Exception):
    pass


def _crc32c_table():
    table = np.zeros(256, dtype=np.uint32)
    for i in range(256):
        c = i
        for _ in range(8):
            c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
        table[i] = c
    return table


_TABLE = _crc32c_table()


def page_crcs(pages):
    """CRC-32C of the first 1020 bytes of every page (array n x 1024), computed over all pages at once."""
    crc = np.full(pages.shape[0], 0xFFFFFFFF, dtype=np.uint32)
    for k in range(PAYLOAD):
        crc = _TABLE[(crc ^ pages[:, k]) & 0xFF] ^ (crc >> np.uint32(8))
    return crc ^ np.uint32(0xFFFFFFFF)


def logical_of(physical):
    return physical // PAGE * PAYLOAD + physical % PAGE


def _local(tag):
    """'{ns}name' -> 'name' for E57's own namespace; extension elements keep '{uri}name'."""
    if tag.startswith("{" + E57_NS + "}"):
        return tag[len(E57_NS) + 2:]
    return tag


def _child(node, name):
    for c in node:
        if _local(c.tag) == name:
            return c
    return None


def _number(node, default=0.0):
    if node is None:
        return default
    text = (node.text or "").strip()
    kind = node.get("type")
    if kind == "Integer":
        return int(text) if text else 0
    if kind == "Float":
        return float(text) if text else 0.0
    if kind == "ScaledInteger":
        raw = int(text) if text else 0
        return raw * float(node.get("scale", "1")) + float(node.get("offset", "0"))
    raise E57Error(f"element {node.tag}: not a number (type {kind})")


class Field:
    def __init__(self, node, name):
        self.name = name
        self.kind = node.get("type")
        if self.kind in ("Integer", "ScaledInteger"):
            self.minimum = int(node.get("minimum", str(-(2 ** 63))))
            self.maximum = int(node.get("maximum", str(2 ** 63 - 1)))
            if self.maximum < self.minimum:
                raise E57Error(f"field {name}: maximum < minimum")
            self.bits = (self.maximum - self.minimum).bit_length()  # holds maximum - minimum
            self.scale = float(node.get("scale", "1"))
            self.offset = float(node.get("offset", "0"))
        elif self.kind == "Float":
            self.bits = 32 if node.get("precision") == "single" else 64
        else:
            raise E57Error(f"field {name}: prototype type {self.kind} is not a terminal number")

    def decode(self, stream, count):
        need = (count * self.bits + 7) // 8
        if len(stream) < need:
            raise E57Error(f"field {self.name}: bytestream of {len(stream)} bytes, {count} records need {need}")
        if self.kind == "Float":
            dtype = "<f4" if self.bits == 32 else "<f8"
            return np.frombuffer(bytes(stream[:need]), dtype=dtype).astype(np.float64)
        if self.bits == 0:
            raw = np.zeros(count, dtype=np.int64)
        elif self.bits <= 56:
            buf = np.frombuffer(bytes(stream) + bytes(8), dtype=np.uint8)
            bit = np.arange(count, dtype=np.int64) * self.bits
            byte = bit // 8
            word = np.zeros(count, dtype=np.uint64)
            for k in range(8):  # the 8 bytes from the value's first byte, little-endian
                word |= buf[byte + k].astype(np.uint64) << np.uint64(8 * k)
            word >>= (bit % 8).astype(np.uint64)
            raw = (word & np.uint64((1 << self.bits) - 1)).astype(np.int64)
        else:  # wide fields: Python integers
            as_int = int.from_bytes(bytes(stream[:need]), "little")
            mask = (1 << self.bits) - 1
            raw = np.array([float((as_int >> (i * self.bits)) & mask) for i in range(count)], dtype=np.float64)
            value = raw + float(self.minimum)
            return value * self.scale + self.offset if self.kind == "ScaledInteger" else value
        value = (raw + self.minimum).astype(np.float64)
        if self.kind == "ScaledInteger":
            value = value * self.scale + self.offset
        return value


def _fields(prototype, prefix=""):
    out = []
    for c in prototype:
        name = prefix + _local(c.tag)
        if c.get("type") in ("Structure", "Vector"):
            out += _fields(c, name + "/")
        else:
            out.append(Field(c, name))
    return out


class E57:
    def __init__(self):
        self.scans = []  # dicts: name, rotation (w x y z), translation, record_count, fields {name: array}
        self.images = []  # dicts: name, representation, encoding ('jpeg' / 'png'), blob (bytes)
        self.xml = None  # the parsed e57Root
        self.logical = b""  # the logical byte stream (pages without their CRCs)


def decode(path):
    data = open(path, "rb").read()
    if len(data) == 0 or len(data) % PAGE:
        raise E57Error(f"{path}: {len(data)} bytes is not a whole number of {PAGE}-byte pages")
    pages = np.frombuffer(data, dtype=np.uint8).reshape(-1, PAGE)
    stored = pages[:, PAYLOAD:].astype(np.uint32)
    stored = (stored[:, 0] << 24) | (stored[:, 1] << 16) | (stored[:, 2] << 8) | stored[:, 3]
    bad = np.nonzero(page_crcs(pages) != stored)[0]
    if len(bad):
        raise E57Error(f"{path}: page {bad[0]}: CRC-32C mismatch")
    logical = pages[:, :PAYLOAD].tobytes()
    sig, major, minor, length, xml_off, xml_len, page_size = struct.unpack_from("<8sIIQQQQ", logical, 0)
    if sig != b"ASTM-E57" or page_size != PAGE or length != len(data):
        raise E57Error(f"{path}: bad header (signature {sig!r}, length {length}, page size {page_size})")
    start = logical_of(xml_off)
    if start + xml_len > len(logical):
        raise E57Error(f"{path}: XML section runs past the end")
    try:
        root = ET.fromstring(logical[start:start + xml_len])
    except ET.ParseError as e:
        raise E57Error(f"{path}: malformed XML: {e}")
    if _local(root.tag) != "e57Root":
        raise E57Error(f"{path}: no e57Root")
    out = E57()
    out.xml = root
    out.logical = logical
    data3d = _child(root, "data3D")
    for entry in (data3d if data3d is not None else []):
        out.scans.append(_scan(path, logical, entry))
    images2d = _child(root, "images2D")
    for entry in (images2d if images2d is not None else []):
        for rep in entry:
            kind = _local(rep.tag)
            if not kind.endswith("Representation"):
                continue
            blob = _child(rep, "jpegImage")
            encoding = "jpeg"
            if blob is None:
                blob, encoding = _child(rep, "pngImage"), "png"
            if blob is None:
                raise E57Error(f"{path}: image without jpegImage / pngImage")
            out.images.append({"name": (_child(entry, "name").text if _child(entry, "name") is not None
                                        else ""),
                               "representation": kind, "encoding": encoding,
                               "blob": _blob(path, logical, blob)})
    return out


def _blob(path, logical, node):
    at = logical_of(int(node.get("fileOffset")))
    length = int(node.get("length"))
    if at + 16 > len(logical) or logical[at] != 0:
        raise E57Error(f"{path}: blob at {node.get('fileOffset')} is not a blob section")
    (section_length,) = struct.unpack_from("<Q", logical, at + 8)
    if length > section_length - 16 or at + section_length > len(logical):
        raise E57Error(f"{path}: blob of {length} bytes does not fit its section")
    return logical[at + 16:at + 16 + length]


def read_compressed_vector(path, logical, points):
    """(record_count, {field name: float64 array}) of a CompressedVector element."""
    count = int(points.get("recordCount"))
    fields = _fields(_child(points, "prototype"))
    at = logical_of(int(points.get("fileOffset")))
    if at + 32 > len(logical) or logical[at] != 1:
        raise E57Error(f"{path}: compressed vector at {points.get('fileOffset')}: sectionId is not 1")
    section_length, data_offset, _ = struct.unpack_from("<QQQ", logical, at + 8)
    end = at + section_length
    if section_length < 32 or end > len(logical):
        raise E57Error(f"{path}: compressed vector section length {section_length} does not fit the file")
    streams = [bytearray() for _ in fields]
    need = [(count * f.bits + 7) // 8 for f in fields]
    pos = logical_of(data_offset) if count > 0 else end
    while any(len(s) < n for s, n in zip(streams, need)):
        if pos + 4 > end:
            raise E57Error(f"{path}: compressed vector ends before its {count} records")
        kind = logical[pos]
        (length_m1,) = struct.unpack_from("<H", logical, pos + 2)
        if kind == 1:
            (n_streams,) = struct.unpack_from("<H", logical, pos + 4)
            if n_streams != len(fields):
                raise E57Error(f"{path}: data packet with {n_streams} bytestreams, prototype has {len(fields)}")
            lengths = struct.unpack_from(f"<{n_streams}H", logical, pos + 6)
            q = pos + 6 + 2 * n_streams
            for i, n in enumerate(lengths):
                streams[i] += logical[q:q + n]
                q += n
            if q > pos + length_m1 + 1:
                raise E57Error(f"{path}: data packet buffers exceed the packet")
        elif kind not in (0, 2):
            raise E57Error(f"{path}: unknown packet type {kind}")
        pos += length_m1 + 1
    return count, {f.name: f.decode(s, count) for f, s in zip(fields, streams)}


def _scan(path, logical, entry):
    points = _child(entry, "points")
    if points is None:
        raise E57Error(f"{path}: data3D entry without points")
    count, values = read_compressed_vector(path, logical, points)
    pose = _child(entry, "pose")
    rotation = [1.0, 0.0, 0.0, 0.0]
    translation = [0.0, 0.0, 0.0]
    if pose is not None:
        r, t = _child(pose, "rotation"), _child(pose, "translation")
        if r is not None:
            rotation = [_number(_child(r, k), d) for k, d in zip("wxyz", (1.0, 0.0, 0.0, 0.0))]
        if t is not None:
            translation = [_number(_child(t, k)) for k in "xyz"]
    name = _child(entry, "name")
    return {"name": name.text if name is not None else "", "rotation": rotation, "translation": translation,
            "record_count": count, "fields": values, "entry": entry}


def cartesian(scan):
    """x, y, z arrays (scanner frame) of a scan's records; spherical ones converted (azimuth from +x
    counter-clockwise, elevation from the xy plane)."""
    f = scan["fields"]
    if "cartesianX" in f:
        return f["cartesianX"], f["cartesianY"], f["cartesianZ"]
    r, az, el = f["sphericalRange"], f["sphericalAzimuth"], f["sphericalElevation"]
    return r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)


def valid_mask(scan):
    """Records that are points: invalid state 0 (or no state field)."""
    f = scan["fields"]
    state = f.get("cartesianInvalidState", f.get("sphericalInvalidState"))
    if state is None:
        return np.ones(scan["record_count"], dtype=bool)
    return state == 0


def world(scan, x, y, z):
    w, qx, qy, qz = scan["rotation"]
    n = math.sqrt(w * w + qx * qx + qy * qy + qz * qz)
    w, qx, qy, qz = w / n, qx / n, qy / n, qz / n
    rot = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - w * qz), 2 * (qx * qz + w * qy)],
                    [2 * (qx * qy + w * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - w * qx)],
                    [2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy)]])
    p = rot @ np.vstack([x, y, z]) + np.array(scan["translation"])[:, None]
    return p[0], p[1], p[2]
