// The native MSH reader (msh_file.hpp) against Gmsh's own API as the independent reference
// (gmsh_api_reader.hpp): the shipped .msh files, and .geo files of tests/data and examples meshed
// by Gmsh and written in MSH 2.2 and 4.1, ASCII and binary, with and without Mesh.SaveAll, must
// give identical meshes (node tags and order, bit-identical coordinates, elements, boundaries).
// Then the refusals of broken and lying files: each names the file and the line or byte.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "../test_files.hpp"
#include "gmsh_api_reader.hpp"
#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/msh_file.hpp"

namespace robin {
namespace {

const std::filesystem::path data_directory = ROBIN_TEST_DATA;
const std::filesystem::path examples_directory = ROBIN_EXAMPLES;

/// Expects `actual` to be `expected` exactly: coordinates compared bit for bit.
void expect_identical(const Mesh& expected, const Mesh& actual, const std::string& label) {
  SCOPED_TRACE(label);
  EXPECT_EQ(actual.dimension, expected.dimension);
  ASSERT_EQ(actual.node_tags, expected.node_tags);
  ASSERT_EQ(actual.nodes.size(), expected.nodes.size());
  for (std::size_t i = 0; i < expected.nodes.size(); ++i) {
    ASSERT_EQ(std::memcmp(actual.nodes[i].data(), expected.nodes[i].data(), 3 * sizeof(double)), 0)
        << "node " << expected.node_tags[i];
  }
  ASSERT_EQ(actual.blocks.size(), expected.blocks.size());
  for (std::size_t b = 0; b < expected.blocks.size(); ++b) {
    EXPECT_EQ(actual.blocks[b].type, expected.blocks[b].type);
    EXPECT_EQ(actual.blocks[b].connectivity, expected.blocks[b].connectivity);
    EXPECT_EQ(actual.blocks[b].tags, expected.blocks[b].tags);
  }
  ASSERT_EQ(actual.boundaries.size(), expected.boundaries.size());
  for (const auto& [name, group] : expected.boundaries) {
    const auto found = actual.boundaries.find(name);
    ASSERT_NE(found, actual.boundaries.end()) << name;
    EXPECT_EQ(found->second.type, group.type) << name;
    EXPECT_EQ(found->second.connectivity, group.connectivity) << name;
  }
}

/// The message of the InputError `read` throws ("" when it throws none).
template <typename Read>
std::string input_error_message(Read&& read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

/// summarize_msh_file agrees with `reference`, the file's mesh read whole: the same dimension
/// and boundary names (an MSH 2.2 file's unnamed groups, known from its elements only, are
/// missing), at least its node count; no summary only for a 2.2 file without $PhysicalNames.
void expect_summary_agrees(const std::filesystem::path& path, const Mesh& reference) {
  const std::optional<MshSummary> summary = summarize_msh_file(path);
  const std::string text = testing::file_text(path);
  const bool old_format = text.rfind("$MeshFormat\n2.2", 0) == 0;
  if (!summary) {
    EXPECT_TRUE(old_format) << path << ": no summary of an MSH 4.1 file";
    EXPECT_EQ(text.find("$PhysicalNames"), std::string::npos) << path << ": names but no summary";
    return;
  }
  EXPECT_EQ(summary->dimension, reference.dimension) << path;
  std::vector<std::string> names;  // an unnamed group is named by its tag
  for (const auto& [name, group] : reference.boundaries) {
    const bool tag = name.find_first_not_of("0123456789") == std::string::npos;
    if (!(old_format && tag)) names.push_back(name);
  }
  std::vector<std::string> listed = summary->boundary_names;
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(listed, names) << path;
  EXPECT_GE(summary->node_count, reference.node_count()) << path;
}

/// Reads `path` with both readers: the same mesh, or both refuse it.
void expect_same_as_gmsh(const std::filesystem::path& path) {
  Mesh reference;
  const std::string reference_error =
      input_error_message([&] { reference = read_msh_with_gmsh_api(path); });
  Mesh native;
  const std::string native_error = input_error_message([&] { native = read_msh_file(path); });
  if (!reference_error.empty()) {
    EXPECT_FALSE(native_error.empty()) << path << ": Gmsh refuses it: " << reference_error;
    return;
  }
  ASSERT_EQ(native_error, "") << path;
  expect_identical(reference, native, path.string());
  EXPECT_EQ(native.source, path.string());
  expect_summary_agrees(path, reference);
}

TEST(MshFile, ShippedMeshFilesReadAsGmshReadsThem) {
  int compared = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data_directory)) {
    const std::filesystem::path& path = entry.path();
    // mesh_gmsh_crash_v22.msh crashes Gmsh itself (the reason for robin-mesh-reader's child)
    if (path.extension() != ".msh" || path.filename() == "mesh_gmsh_crash_v22.msh") continue;
    expect_same_as_gmsh(path);
    ++compared;
  }
  EXPECT_GE(compared, 5);
}

/// A .geo meshed with `options`, written in every format, each read by both readers.
void expect_every_format_same_as_gmsh(const std::filesystem::path& geo,
                                      const MeshReadOptions& options) {
  SCOPED_TRACE(geo.string() + " size " + std::to_string(options.size) + " order " +
               std::to_string(options.element_order) + (options.recombine ? " recombined" : ""));
  const testing::TemporaryDirectory directory("msh-file-test");
  std::vector<MshWriting> writings;
  for (const double version : {2.2, 4.1}) {
    for (const bool binary : {false, true}) {
      for (const bool save_all : {false, true}) {
        const std::string name = std::string(version == 2.2 ? "v22" : "v41") +
                                 (binary ? "_binary" : "_ascii") + (save_all ? "_all" : "") +
                                 ".msh";
        writings.push_back({directory.path() / name, version, binary, save_all});
      }
    }
  }
  write_msh_with_gmsh_api(geo, options, writings);
  for (const MshWriting& writing : writings) expect_same_as_gmsh(writing.path);
}

TEST(MshFile, PlaneMeshesInEveryFormatReadAsGmshReadsThem) {
  expect_every_format_same_as_gmsh(data_directory / "mesh_square.geo", {});
  expect_every_format_same_as_gmsh(data_directory / "mesh_clockwise.geo", {.element_order = 2});
  expect_every_format_same_as_gmsh(data_directory / "mesh_irregular.geo", {.recombine = true});
  expect_every_format_same_as_gmsh(data_directory / "mesh_mixed.geo", {});
  expect_every_format_same_as_gmsh(data_directory / "mesh_no_surface_group.geo", {});
  expect_every_format_same_as_gmsh(data_directory / "case_lower.geo", {});
  expect_every_format_same_as_gmsh(examples_directory / "meshes" / "block_lower.geo",
                                   {.size = 0.05});
  expect_every_format_same_as_gmsh(examples_directory / "meshes" / "hertz_upper.geo", {});
  expect_every_format_same_as_gmsh(examples_directory / "meshes" / "arch_keystone.geo",
                                   {.element_order = 2});
}

TEST(MshFile, SolidMeshesInEveryFormatReadAsGmshReadsThem) {
  expect_every_format_same_as_gmsh(data_directory / "solid_block.geo", {});
  expect_every_format_same_as_gmsh(data_directory / "solid_block.geo", {.element_order = 2});
  expect_every_format_same_as_gmsh(data_directory / "solid_block_hexahedra.geo", {});
  expect_every_format_same_as_gmsh(examples_directory / "meshes" / "solid_patch_lower.geo", {});
}

// ---------------------------------------------------------------------------------------------
// Refusals

/// The message of parsing `bytes` as the file "bad.msh".
std::string refusal(const std::string& bytes) {
  return input_error_message([&] { parse_msh_file(bytes, "bad.msh"); });
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(MshFile, TruncatedFilesAreRefusedNamingTheLineOrByte) {
  const testing::TemporaryDirectory directory("msh-file-truncated");
  const std::filesystem::path binary = directory.path() / "square_binary.msh";
  write_msh_with_gmsh_api(data_directory / "mesh_square.geo", {}, {{binary, 4.1, true, false}});
  for (const std::filesystem::path& path :
       {data_directory / "mesh_square_v22.msh", data_directory / "mesh_square_v41.msh", binary}) {
    const std::string text = testing::file_text(path);
    const Mesh whole = parse_msh_file(text, "whole.msh");
    for (std::size_t length = 0; length < text.size(); ++length) {
      Mesh mesh;
      const std::string message =
          input_error_message([&] { mesh = parse_msh_file(text.substr(0, length), "bad.msh"); });
      if (message.empty()) {
        // only the end of the last section may be cut without losing anything
        expect_identical(whole, mesh, path.string() + " cut at " + std::to_string(length));
        EXPECT_GE(length, text.rfind("$EndElements")) << path;
        continue;
      }
      EXPECT_EQ(message.rfind("mesh file 'bad.msh'", 0), 0u) << message;
    }
  }
}

TEST(MshFile, BillionsOfNodesClaimedInASmallFileAreRefusedBeforeAllocating) {
  const std::string square = testing::file_text(data_directory / "mesh_square_v41.msh");
  const std::string claims = replaced(square, "9 12 1 12", "9 1500000000 1 12");
  const std::size_t header_end = claims.find("9 1500000000 1 12") + 17;
  EXPECT_EQ(refusal(claims),
            "mesh file 'bad.msh' line 25: $Nodes declares 1500000000 nodes but "
            "the file has " +
                std::to_string(claims.size() - header_end) + " bytes left");
  const std::string old_format = testing::file_text(data_directory / "mesh_square_v22.msh");
  EXPECT_NE(refusal(replaced(old_format, "$Nodes\n12\n", "$Nodes\n1500000000\n"))
                .find("mesh file 'bad.msh' line 12: $Nodes declares 1500000000 nodes but the "
                      "file has "),
            std::string::npos);
  EXPECT_NE(refusal(replaced(old_format, "$Elements\n", "$Elements\n99999999"))
                .find("$Elements declares 9999999922 elements"),
            std::string::npos);
  EXPECT_NE(refusal(replaced(square, "4\n1 1 \"bottom\"", "400000000\n1 1 \"bottom\""))
                .find("line 5: $PhysicalNames declares 400000000 names"),
            std::string::npos);
  EXPECT_NE(refusal(replaced(square, "5 4 1 0\n", "5 4 1 3000000000\n"))
                .find("line 12: $Entities declares 3000000000 volumes but the file has"),
            std::string::npos);
}

TEST(MshFile, LyingBinaryCountsAreRefusedNamingTheByte) {
  const testing::TemporaryDirectory directory("msh-file-binary");
  const std::filesystem::path path = directory.path() / "square.msh";
  write_msh_with_gmsh_api(data_directory / "mesh_square.geo", {}, {{path, 4.1, true, false}});
  const std::string text = testing::file_text(path);
  const std::size_t nodes = text.find("$Nodes\n") + 7;  // numEntityBlocks, numNodes, ...
  std::string lying = text;
  const std::uint64_t claimed = std::uint64_t{1} << 40;
  std::memcpy(&lying[nodes + 8], &claimed, sizeof claimed);
  EXPECT_EQ(refusal(lying), "mesh file 'bad.msh' byte " + std::to_string(nodes + 32) +
                                ": $Nodes declares 1099511627776 nodes but the file has " +
                                std::to_string(text.size() - nodes - 32) + " bytes left");
  // the endianness word: byte-swapped, then any other value
  const std::size_t word = text.find("4.1 1 8\n") + 8;
  std::string swapped = text;
  const std::int32_t big_endian_one = 0x01000000, two = 2;
  std::memcpy(&swapped[word], &big_endian_one, 4);
  EXPECT_NE(refusal(swapped).find("mesh file 'bad.msh' byte " + std::to_string(word) +
                                  ": the binary file was written on a big-endian machine"),
            std::string::npos)
      << refusal(swapped);
  std::memcpy(&swapped[word], &two, 4);
  EXPECT_EQ(refusal(swapped), "mesh file 'bad.msh' byte " + std::to_string(word) +
                                  ": the endianness word is 2, not 1");
}

TEST(MshFile, MalformedSectionsAreRefusedNamingTheLine) {
  const std::string old_format = testing::file_text(data_directory / "mesh_square_v22.msh");
  // the first element line is line 28: "1 1 2 1 1 1 5" (an edge of physical group 1)
  EXPECT_EQ(refusal(replaced(old_format, "\n1 1 2 1 1 1 5\n", "\n1 99 2 1 1 1 5\n")),
            "mesh file 'bad.msh' line 28: unknown element type 99");
  EXPECT_EQ(refusal(replaced(old_format, "$EndNodes\n", "")),
            "mesh file 'bad.msh' line 25: expected $EndNodes, found '$Elements'");
  EXPECT_EQ(refusal(replaced(old_format, "2.2 0 8", "3.0 0 8")),
            "mesh file 'bad.msh' line 2: MSH version '3.0' is not supported: write the mesh as "
            "MSH 4.1 or 2.2");
  EXPECT_EQ(refusal(replaced(old_format, "2.2 0 8", "2.2 0 4")),
            "mesh file 'bad.msh' line 2: data size 4 is not 8");
  EXPECT_EQ(refusal("this is not a mesh\n"),
            "mesh file 'bad.msh' line 1: the file does not begin with $MeshFormat: not a Gmsh MSH "
            "file");
  EXPECT_EQ(refusal(replaced(old_format, "\n3 1 1 0\n", "\n3 one 1 0\n")),
            "mesh file 'bad.msh' line 15: node x 'one' is not a finite real number");
  const std::size_t last_line = std::count(old_format.begin(), old_format.end(), '\n') + 1;
  EXPECT_EQ(refusal(old_format + "$Comments\nno end\n"),
            "mesh file 'bad.msh' line " + std::to_string(last_line) +
                ": section $Comments has no $EndComments");
  // an element naming a node $Nodes does not define
  EXPECT_EQ(refusal(replaced(old_format, "\n1 1 2 1 1 1 5\n", "\n1 1 2 1 1 1 77\n")),
            "mesh file 'bad.msh': an element uses node tag 77, which $Nodes does not define");
}

TEST(MshFile, SectionsTheReaderDoesNotUseAreSkipped) {
  const std::string old_format = testing::file_text(data_directory / "mesh_square_v22.msh");
  const Mesh plain = parse_msh_file(old_format, "plain.msh");
  const std::string extra =
      replaced(old_format, "$Nodes\n",
               "$Comments\n$Nodes inside a comment\n$EndComments\n$NodeData\n1\n\"u\"\n1\n0.0\n3\n"
               "0\n1\n1\n1 0.5\n$EndNodeData\n$Nodes\n");
  expect_identical(plain, parse_msh_file(extra + "$Periodic\n0\n$EndPeriodic\n", "extra.msh"),
                   "extra sections");
}

}  // namespace
}  // namespace robin
