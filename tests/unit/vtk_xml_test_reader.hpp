#pragma once
// Test-only readers of VTK XML files (.vtu, .pvd), independent of the writer.
//
// read_vtk_xml: Python's xml.etree parses the XML part (so it must be well-formed XML) and the
// script decodes every array itself: inline ASCII text, or appended raw binary data with the
// header_type's size words, uncompressed (one byte-count word) or in vtkZLibDataCompressor's
// layout ([blocks, block size, last block size, compressed sizes...], then zlib streams), in the
// file's byte_order. It converts the file to JSON, which the test reads with nlohmann_json.
// Values compare exactly (binary doubles are copied; decimal text goes through correctly
// rounded conversions on both sides); NaN becomes null. String arrays (VTK's ASCII form: the
// character codes, each string ended by 0) become lists of strings.
//
// Layout of the returned document:
//   {"root": {attributes of VTKFile},
//    "datasets": [{attributes of DataSet}, ...]                    (Collection files)
//    "field_data": [array...],                                    (UnstructuredGrid files)
//    "pieces": [{"attributes": {...}, "PointData": [array...], "CellData": [...],
//                "Points": [...], "Cells": [...]}]}                 (UnstructuredGrid files)
// with array = {"attributes": {...}, "values": [numbers]} (integers for Int*/UInt* types).
//
// read_vtu_with_vtk: the file read by VTK's own vtkXMLUnstructuredGridReader (ParaView's VTK,
// python3-paraview's vtkmodules), as JSON:
//   {"points": [x, y, z, ...], "connectivity": [...], "offsets": [...] (end of each cell),
//    "types": [...], "point_data": {name: {"components": n, "component_names": [...],
//    "values": [...]}}, "cell_data": {...}, "field_data": {name: [strings]}}

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "../test_files.hpp"

namespace robin::test {

inline constexpr const char* vtk_xml_to_json_script = R"python(
import json, math, struct, sys, zlib, xml.etree.ElementTree as ET
data = open(sys.argv[1], 'rb').read()
marker = data.find(b'<AppendedData')
appended = b''
if marker >= 0:
    appended = data[data.index(b'_', data.index(b'>', marker)) + 1:]
    data = data[:marker] + b'</VTKFile>'
root = ET.fromstring(data)
order = '<' if root.get('byte_order', 'LittleEndian') == 'LittleEndian' else '>'
word = 'Q' if root.get('header_type', 'UInt32') == 'UInt64' else 'I'
word_size = struct.calcsize(word)
compressed = root.get('compressor')
if compressed not in (None, 'vtkZLibDataCompressor'):
    raise SystemExit('unsupported compressor ' + compressed)
codes = {'Float64': 'd', 'Float32': 'f', 'Int64': 'q', 'Int32': 'i', 'UInt64': 'Q',
         'UInt32': 'I', 'Int8': 'b', 'UInt8': 'B'}
def words(position, count):
    return list(struct.unpack_from(order + word * count, appended, position))
def appended_bytes(offset):
    if compressed is None:
        size = words(offset, 1)[0]
        start = offset + word_size
        return appended[start:start + size]
    blocks, block_size, last_size = words(offset, 3)
    sizes = words(offset + 3 * word_size, blocks)
    position = offset + (3 + blocks) * word_size
    raw = b''
    for size in sizes:
        raw += zlib.decompress(appended[position:position + size])
        position += size
    expected = block_size * blocks if last_size == 0 else block_size * (blocks - 1) + last_size
    if len(raw) != expected:
        raise SystemExit('decompressed %d bytes, the header says %d' % (len(raw), expected))
    return raw
def finite(value):
    return None if isinstance(value, float) and math.isnan(value) else value
def strings_of(raw):
    return [text.decode() for text in raw.split(b'\0')[:-1]]
def array(element):
    kind = element.get('type', '')
    attributes = dict(element.attrib)
    if element.get('format') == 'appended':
        raw = appended_bytes(int(element.get('offset')))
        if kind == 'String':
            return {'attributes': attributes, 'values': strings_of(raw)}
        code = codes[kind]
        values = list(struct.unpack(order + code * (len(raw) // struct.calcsize(code)), raw))
    else:
        text = (element.text or '').split()
        if kind == 'String':
            return {'attributes': attributes,
                    'values': strings_of(bytes(int(w) for w in text))}
        integer = kind.startswith(('Int', 'UInt'))
        values = [int(w) if integer else float(w) for w in text]
    return {'attributes': attributes, 'values': [finite(v) for v in values]}
document = {'root': dict(root.attrib)}
if root.get('type') == 'Collection':
    document['datasets'] = [dict(d.attrib) for d in root.find('Collection').findall('DataSet')]
else:
    grid = root.find('UnstructuredGrid')
    field_data = grid.find('FieldData')
    document['field_data'] = [] if field_data is None else [
        array(a) for a in field_data.findall('DataArray')]
    pieces = []
    for piece in grid.findall('Piece'):
        entry = {'attributes': dict(piece.attrib)}
        for section in ('PointData', 'CellData', 'Points', 'Cells'):
            found = piece.find(section)
            entry[section] = [] if found is None else [array(a) for a in found.findall('DataArray')]
        pieces.append(entry)
    document['pieces'] = pieces
with open(sys.argv[2], 'w') as out:
    json.dump(document, out, allow_nan=False)
)python";

inline constexpr const char* vtk_reader_to_json_script = R"python(
import json, math, sys
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
from vtkmodules.util.numpy_support import vtk_to_numpy
reader = vtkXMLUnstructuredGridReader()
reader.SetFileName(sys.argv[1])
reader.Update()
if reader.GetErrorCode() != 0:
    raise SystemExit('VTK could not read ' + sys.argv[1])
grid = reader.GetOutput()
def values(array):
    return [None if isinstance(v, float) and math.isnan(v) else v
            for v in vtk_to_numpy(array).ravel().tolist()]
def section(data):
    arrays = {}
    for k in range(data.GetNumberOfArrays()):
        array = data.GetArray(k)
        components = array.GetNumberOfComponents()
        arrays[array.GetName()] = {
            'components': components,
            'component_names': [array.GetComponentName(c) or '' for c in range(components)],
            'values': values(array)}
    return arrays
field_data = grid.GetFieldData()
strings = {}
for k in range(field_data.GetNumberOfArrays()):
    array = field_data.GetAbstractArray(k)
    strings[array.GetName()] = [array.GetValue(i) for i in range(array.GetNumberOfValues())]
cells = grid.GetCells()
document = {
    'points': values(grid.GetPoints().GetData()) if grid.GetNumberOfPoints() else [],
    'connectivity': values(cells.GetConnectivityArray()),
    'offsets': values(cells.GetOffsetsArray())[1:],
    'types': [grid.GetCellType(c) for c in range(grid.GetNumberOfCells())],
    'point_data': section(grid.GetPointData()),
    'cell_data': section(grid.GetCellData()),
    'field_data': strings}
with open(sys.argv[2], 'w') as out:
    json.dump(document, out, allow_nan=False)
)python";

/// Runs `script` with /usr/bin/python3 on `file`, returning the JSON it writes.
inline nlohmann::json run_reader_script(const char* script_text, const std::string& script_name,
                                        const std::filesystem::path& file) {
  const std::filesystem::path directory = file.parent_path();
  const std::filesystem::path script = directory / script_name;
  const std::filesystem::path output = file.string() + "." + script_name + ".json";
  std::ofstream(script) << script_text;
  const std::string command = "/usr/bin/python3 '" + script.string() + "' '" + file.string() +
                              "' '" + output.string() + "'";
  if (std::system(command.c_str()) != 0) {
    throw std::runtime_error("the Python reader " + script_name + " rejected " + file.string());
  }
  std::ifstream in(output);
  return nlohmann::json::parse(in);
}

/// Parses `file` (written beforehand) into the JSON layout above; fails the test on error.
inline nlohmann::json read_vtk_xml(const std::filesystem::path& file) {
  return run_reader_script(vtk_xml_to_json_script, "vtk_xml_to_json.py", file);
}

/// Reads the .vtu `file` with VTK's reader into the JSON layout above.
inline nlohmann::json read_vtu_with_vtk(const std::filesystem::path& file) {
  return run_reader_script(vtk_reader_to_json_script, "vtk_reader_to_json.py", file);
}

/// The DataArray called `name` in a section (a JSON list of arrays); throws if absent.
inline const nlohmann::json& find_array(const nlohmann::json& section, const std::string& name) {
  for (const nlohmann::json& array : section) {
    if (array["attributes"].value("Name", "") == name) return array;
  }
  throw std::runtime_error("no DataArray named " + name);
}

/// The tests' scratch directory (test_files.hpp).
using robin::testing::TemporaryDirectory;

}  // namespace robin::test
