"""A reader of VTK XML UnstructuredGrid files (.vtu), as robin-contact writes them, into NumPy
arrays: standard library and NumPy only.

Data arrays may be written as text (format="ascii"), inline base64 (format="binary") or in the
appended section (format="appended", encoding "raw" or "base64"); binary data may be
uncompressed or compressed with vtkZLibDataCompressor (zlib blocks); headers are UInt32 or
UInt64 (header_type), in the file's byte order. String arrays (type="String") become lists of
str. The layouts are those of the VTK file format documentation ("VTK XML formats").
"""

import base64
import struct
import xml.etree.ElementTree as ElementTree
import zlib

import numpy as np

_TYPES = {
    "Int8": "i1", "UInt8": "u1", "Int16": "i2", "UInt16": "u2", "Int32": "i4", "UInt32": "u4",
    "Int64": "i8", "UInt64": "u8", "Float32": "f4", "Float64": "f8", "String": "u1",
}


class VtuError(Exception):
    """A .vtu file this reader cannot read (the message names the file and the problem)."""


class VtuFile:
    """One UnstructuredGrid piece: points (N x 3), cells (connectivity, offsets, types), the
    point and cell data by name (arrays of N or N x components values; String arrays as lists
    of str), and the field data (FieldData) by name."""

    def __init__(self, points, connectivity, offsets, types, point_data, cell_data, field_data):
        self.points = points
        self.connectivity = connectivity
        self.offsets = offsets
        self.types = types
        self.point_data = point_data
        self.cell_data = cell_data
        self.field_data = field_data

    def cells(self):
        """The node indices of each cell, as a list of arrays."""
        starts = np.concatenate(([0], self.offsets[:-1]))
        return [self.connectivity[begin:end] for begin, end in zip(starts, self.offsets)]


def _split_appended(data):
    """(the XML text with the appended section emptied, the raw appended bytes or None)."""
    start = data.find(b"<AppendedData")
    if start < 0:
        return data, None
    marker = data.find(b"_", data.find(b">", start))
    end = data.rfind(b"</AppendedData>")
    if marker < 0 or end < marker:
        raise VtuError("malformed AppendedData section")
    return data[:marker] + data[end:], data[marker + 1:end]


class _Decoder:
    def __init__(self, root, appended, appended_encoding):
        self.byte_order = "<" if root.get("byte_order", "LittleEndian") == "LittleEndian" else ">"
        header_type = root.get("header_type", "UInt32")
        if header_type not in ("UInt32", "UInt64"):
            raise VtuError("unsupported header_type %s" % header_type)
        self.header_size = 4 if header_type == "UInt32" else 8
        self.header_format = self.byte_order + ("I" if self.header_size == 4 else "Q")
        compressor = root.get("compressor")
        if compressor not in (None, "", "vtkZLibDataCompressor"):
            raise VtuError("unsupported compressor %s" % compressor)
        self.compressed = bool(compressor)
        self.appended = appended
        self.appended_encoding = appended_encoding

    def _words(self, data, count):
        size = self.header_size * count
        if len(data) < size:
            raise VtuError("truncated binary header")
        return struct.unpack(self.byte_order + ("I" if self.header_size == 4 else "Q") * count,
                             data[:size])

    def _record(self, data):
        """The payload of one binary record at the start of `data` (raw bytes)."""
        if not self.compressed:
            (size,) = self._words(data, 1)
            payload = data[self.header_size:self.header_size + size]
            if len(payload) != size:
                raise VtuError("truncated binary data")
            return payload
        (blocks,) = self._words(data, 1)
        words = self._words(data, 3 + blocks)
        compressed_sizes = words[3:]
        position = self.header_size * (3 + blocks)
        parts = []
        for size in compressed_sizes:
            parts.append(zlib.decompress(data[position:position + size]))
            position += size
        return b"".join(parts)

    def _inline_binary(self, text):
        """The payload of a format="binary" array: base64 of the header, then (compressed:
        separately) of the data."""
        text = "".join(text.split()).encode("ascii")
        if not self.compressed:
            return self._record(base64.b64decode(text))
        first = base64.b64decode(text[:_base64_length(self.header_size)])
        (blocks,) = self._words(first, 1)
        header_length = _base64_length(self.header_size * (3 + blocks))
        header = base64.b64decode(text[:header_length])
        compressed_sizes = self._words(header, 3 + blocks)[3:]
        data = base64.b64decode(text[header_length:])
        parts, position = [], 0
        for size in compressed_sizes:
            parts.append(zlib.decompress(data[position:position + size]))
            position += size
        return b"".join(parts)

    def array(self, element):
        """The values of a DataArray element: a NumPy array (N x components when components > 1)
        or, for type="String", a list of str."""
        kind = element.get("type")
        if kind not in _TYPES:
            raise VtuError("unsupported DataArray type %s (%s)" % (kind, element.get("Name")))
        form = element.get("format", "ascii")
        if form == "ascii":
            values = np.array((element.text or "").split(),
                              dtype=np.float64 if kind.startswith("Float") else np.int64)
            values = values.astype(_TYPES[kind])
        else:
            if form == "binary":
                payload = self._inline_binary(element.text or "")
            elif form == "appended":
                if self.appended is None:
                    raise VtuError("format=\"appended\" without an AppendedData section")
                offset = int(element.get("offset", "0"))
                if self.appended_encoding == "base64":
                    raise VtuError("base64 appended data is not supported")
                payload = self._record(self.appended[offset:])
            else:
                raise VtuError("unsupported DataArray format %s" % form)
            values = np.frombuffer(payload, dtype=np.dtype(self.byte_order + _TYPES[kind]))
        if kind == "String":
            return [bytes(part).decode("utf-8") for part in bytes(values.astype("u1")).split(b"\0")[:-1]]
        components = int(element.get("NumberOfComponents", "1"))
        values = np.array(values)  # writable, native byte order
        return values.reshape(-1, components) if components > 1 else values


def _base64_length(size):
    return 4 * ((size + 2) // 3)


def _named_arrays(decoder, section):
    if section is None:
        return {}
    return {element.get("Name"): decoder.array(element) for element in section.findall("DataArray")}


def read_vtu(path):
    """The VtuFile of the .vtu file at `path`. Raises VtuError for what it cannot read."""
    with open(path, "rb") as file:
        data = file.read()
    try:
        text, appended = _split_appended(data)
        root = ElementTree.fromstring(text)
        if root.tag != "VTKFile" or root.get("type") != "UnstructuredGrid":
            raise VtuError("not a VTK UnstructuredGrid file")
        appended_section = root.find("AppendedData")
        encoding = appended_section.get("encoding", "raw") if appended_section is not None else None
        decoder = _Decoder(root, appended, encoding)
        grid = root.find("UnstructuredGrid")
        pieces = grid.findall("Piece")
        if len(pieces) != 1:
            raise VtuError("expected one Piece, found %d" % len(pieces))
        piece = pieces[0]
        cells = _named_arrays(decoder, piece.find("Cells"))
        points = decoder.array(piece.find("Points").find("DataArray"))
        result = VtuFile(points=np.asarray(points, dtype=np.float64).reshape(-1, 3),
                         connectivity=np.asarray(cells["connectivity"], dtype=np.int64),
                         offsets=np.asarray(cells["offsets"], dtype=np.int64),
                         types=np.asarray(cells["types"], dtype=np.int64),
                         point_data=_named_arrays(decoder, piece.find("PointData")),
                         cell_data=_named_arrays(decoder, piece.find("CellData")),
                         field_data=_named_arrays(decoder, grid.find("FieldData")))
    except (ElementTree.ParseError, KeyError, AttributeError, ValueError, zlib.error,
            struct.error) as error:
        raise VtuError("%s: %s" % (path, error)) from error
    except VtuError as error:
        raise VtuError("%s: %s" % (path, error)) from error
    if len(result.points) != int(piece.get("NumberOfPoints")):
        raise VtuError("%s: %d points, NumberOfPoints says %s"
                       % (path, len(result.points), piece.get("NumberOfPoints")))
    return result
