"""robin_contact.read_vtu against files assembled here byte by byte from the layouts of the VTK
file format documentation, with known values: arrays as text (format="ascii"), inline base64
(format="binary") and in the appended raw section, uncompressed and in zlib blocks
(vtkZLibDataCompressor), with UInt32 and UInt64 headers. The files robin-contact's tools write
are read in test_scripting.py."""

import base64
import os
import struct
import sys
import tempfile
import unittest
import zlib

import numpy as np

import support  # noqa: F401  (the python directory on sys.path)
from robin_contact import VtuError, read_vtu

POINTS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
                   [0.5, 1.5, 0.0]])
TRIANGLES = np.array([[0, 1, 2], [0, 2, 3], [3, 2, 4]])
DISPLACEMENT = np.array([[0.1, -0.2, 0.0], [0.3, 0.25, 0.0], [-1e-9, 7.0, 0.0], [2.0, 3.0, 0.0],
                         [1e30, -1e-30, 0.0]])
PRESSURE = np.array([1.5, -2.25, 1e-12])


def vtu_file(form="appended", compressed=False, header="UInt64", block_size=16):
    """A .vtu file of the test arrays, encoded here from the layout of the VTK documentation:
    form "ascii" (numbers as text), "binary" (inline base64) or "appended" (raw section). A
    binary record is its header (the byte count; compressed: the block count, the block size,
    the last block's size and the compressed sizes) followed by the data; inline, a compressed
    record's header and data are base64-encoded separately."""
    word = "<Q" if header == "UInt64" else "<I"

    def header_and_data(values):
        data = values.tobytes()
        if not compressed:
            return struct.pack(word, len(data)), data
        blocks = [data[k:k + block_size] for k in range(0, len(data), block_size)]
        packed = [zlib.compress(block) for block in blocks]
        words = [len(blocks), block_size, len(data) % block_size] + [len(b) for b in packed]
        return b"".join(struct.pack(word, value) for value in words), b"".join(packed)

    arrays = [
        ("String", "boundary_names", 1, np.frombuffer(b"contact\0top\0", dtype="u1"),
         "FieldData"),
        ("Float64", "displacement", 3, DISPLACEMENT.astype("<f8"), "PointData"),
        ("Float64", "pressure", 1, PRESSURE.astype("<f8"), "CellData"),
        ("Int32", "boundary_id", 1, np.array([-1, 0, 2], dtype="<i4"), "CellData"),
        ("Float64", "Points", 3, POINTS.astype("<f8"), "Points"),
        ("Int64", "connectivity", 1, TRIANGLES.ravel().astype("<i8"), "Cells"),
        ("Int64", "offsets", 1, np.array([3, 6, 9], dtype="<i8"), "Cells"),
        ("UInt8", "types", 1, np.array([5, 5, 5], dtype="u1"), "Cells"),
    ]
    appended, elements = b"", {}
    for kind, name, components, values, section in arrays:
        start = '<DataArray type="%s" Name="%s" NumberOfComponents="%d" format="%s"' % (
            kind, name, components, form)
        if form == "ascii":
            element = start + ">" + " ".join(repr(value) for value in values.ravel().tolist())
            element += "</DataArray>"
        elif form == "binary":
            head, data = header_and_data(values)
            encoded = (base64.b64encode(head) + base64.b64encode(data) if compressed
                       else base64.b64encode(head + data))
            element = start + ">\n" + encoded.decode("ascii") + "\n</DataArray>"
        else:
            element = start + ' offset="%d"/>' % len(appended)
            appended += b"".join(header_and_data(values))
        elements.setdefault(section, []).append(element)
    compressor = ' compressor="vtkZLibDataCompressor"' if compressed else ""
    text = ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" '
            'byte_order="LittleEndian" header_type="%s"%s>\n<UnstructuredGrid>\n'
            '<FieldData>%s</FieldData>\n<Piece NumberOfPoints="5" NumberOfCells="3">\n'
            '<PointData>%s</PointData><CellData>%s</CellData>\n<Points>%s</Points>\n'
            '<Cells>%s</Cells>\n</Piece>\n</UnstructuredGrid>\n'
            % (header, compressor, *("".join(elements[section]) for section in
                                     ("FieldData", "PointData", "CellData", "Points", "Cells"))))
    if form != "appended":
        return (text + "</VTKFile>\n").encode("ascii")
    return (text.encode("ascii") + b'<AppendedData encoding="raw">\n   _' + appended
            + b"\n</AppendedData>\n</VTKFile>\n")


class HandEncodedFiles(unittest.TestCase):
    def check(self, data):
        with tempfile.TemporaryDirectory() as directory:
            path = os.path.join(directory, "body.vtu")
            with open(path, "wb") as file:
                file.write(data)
            body = read_vtu(path)
        np.testing.assert_array_equal(body.points, POINTS)
        np.testing.assert_array_equal(body.connectivity, TRIANGLES.ravel())
        np.testing.assert_array_equal(body.point_data["displacement"], DISPLACEMENT)
        np.testing.assert_array_equal(body.cell_data["pressure"], PRESSURE)
        np.testing.assert_array_equal(body.cell_data["boundary_id"], [-1, 0, 2])
        np.testing.assert_array_equal(body.offsets, [3, 6, 9])
        np.testing.assert_array_equal(body.types, [5, 5, 5])  # VTK_TRIANGLE
        self.assertEqual([list(cell) for cell in body.cells()], TRIANGLES.tolist())
        self.assertEqual(body.field_data["boundary_names"], ["contact", "top"])

    def test_ascii(self):
        self.check(vtu_file("ascii"))

    def test_inline_base64(self):
        self.check(vtu_file("binary"))

    def test_inline_base64_zlib_blocks(self):
        self.check(vtu_file("binary", compressed=True))

    def test_appended_raw_uint64_headers(self):
        self.check(vtu_file())

    def test_appended_raw_uint32_headers(self):
        self.check(vtu_file(header="UInt32"))

    def test_appended_zlib_blocks_uint64_headers(self):
        # 16-byte blocks: several blocks per array, a partial last block for some
        self.check(vtu_file(compressed=True))

    def test_appended_zlib_one_block_uint32_headers(self):
        self.check(vtu_file(compressed=True, header="UInt32", block_size=1 << 15))

    def test_truncated_file_is_a_vtu_error_naming_the_file(self):
        data = vtu_file(compressed=True)
        cut = data[:data.find(b"_") + 40] + b"\n</AppendedData>\n</VTKFile>\n"
        with tempfile.TemporaryDirectory() as directory:
            path = os.path.join(directory, "cut.vtu")
            with open(path, "wb") as file:
                file.write(cut)
            with self.assertRaises(VtuError) as raised:
                read_vtu(path)
            self.assertIn("cut.vtu", str(raised.exception))


if __name__ == "__main__":
    sys.exit(unittest.main())
