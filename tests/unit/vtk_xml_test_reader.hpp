#pragma once
// Test-only reader of VTK XML files (.vtu, .pvd), independent of the writer: Python's
// xml.etree parses the file (so it must be well-formed XML) and converts it to JSON, which
// the test reads with nlohmann_json. Decimal text -> double goes through correctly rounded
// conversions on both sides, so values compare exactly.
//
// Layout of the returned document:
//   {"root": {attributes of VTKFile},
//    "datasets": [{attributes of DataSet}, ...]                    (Collection files)
//    "pieces": [{"attributes": {...}, "PointData": [array...], "CellData": [...],
//                "Points": [...], "Cells": [...]}]}                 (UnstructuredGrid files)
// with array = {"attributes": {...}, "values": [numbers]} (integers for Int*/UInt* types).

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <system_error>

#include <unistd.h>

namespace robin::test {

inline constexpr const char* vtk_xml_to_json_script = R"python(
import json, sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
def array(element):
    words = (element.text or '').split()
    integer = element.get('type', '').startswith(('Int', 'UInt'))
    return {'attributes': dict(element.attrib),
            'values': [int(w) if integer else float(w) for w in words]}
document = {'root': dict(root.attrib)}
if root.get('type') == 'Collection':
    document['datasets'] = [dict(d.attrib) for d in root.find('Collection').findall('DataSet')]
else:
    pieces = []
    for piece in root.find('UnstructuredGrid').findall('Piece'):
        entry = {'attributes': dict(piece.attrib)}
        for section in ('PointData', 'CellData', 'Points', 'Cells'):
            found = piece.find(section)
            entry[section] = [] if found is None else [array(a) for a in found.findall('DataArray')]
        pieces.append(entry)
    document['pieces'] = pieces
with open(sys.argv[2], 'w') as out:
    json.dump(document, out)
)python";

/// Parses `file` (written beforehand) into the JSON layout above; fails the test on error.
inline nlohmann::json read_vtk_xml(const std::filesystem::path& file) {
  const std::filesystem::path directory = file.parent_path();
  const std::filesystem::path script = directory / "vtk_xml_to_json.py";
  const std::filesystem::path output = file.string() + ".json";
  std::ofstream(script) << vtk_xml_to_json_script;
  const std::string command = "/usr/bin/python3 '" + script.string() + "' '" + file.string() +
                              "' '" + output.string() + "'";
  if (std::system(command.c_str()) != 0) {
    throw std::runtime_error("the Python XML reader rejected " + file.string());
  }
  std::ifstream in(output);
  return nlohmann::json::parse(in);
}

/// The DataArray called `name` in a section (a JSON list of arrays); throws if absent.
inline const nlohmann::json& find_array(const nlohmann::json& section, const std::string& name) {
  for (const nlohmann::json& array : section) {
    if (array["attributes"].value("Name", "") == name) return array;
  }
  throw std::runtime_error("no DataArray named " + name);
}

/// A fresh empty directory under the system temporary directory (named after the test and the
/// process id, so concurrent runs do not collide), removed on destruction.
class TemporaryDirectory {
 public:
  explicit TemporaryDirectory(const std::string& stem) {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            (stem + "_" + (test ? std::string(test->name()) : std::string("global")) + "_" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TemporaryDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace robin::test
