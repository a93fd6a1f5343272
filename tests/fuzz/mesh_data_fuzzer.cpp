// libFuzzer harness: the wire mesh decoder. Every input is parsed as a serialized
// robin.protocol.MeshData (inputs that do not parse are skipped) and decoded with
// robin::decode_mesh(data, "fuzz"), the server's gate for meshes from the wire. Only
// robin::InputError may leave it; any other exception, a crash, a leak or undefined behaviour
// is a bug. A mesh the decoder accepts must also survive the round trip: encode_mesh of it
// decodes again, to the same nodes, cells and boundaries.

#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "mesh_codec.hpp"
#include "numerics/errors.hpp"
#include "robin.pb.h"

namespace {

[[noreturn]] void fail(const char* problem) {
  std::fprintf(stderr, "robin-fuzz-mesh-data: %s\n", problem);
  std::abort();
}

bool same_mesh(const robin::Mesh& a, const robin::Mesh& b) {
  if (a.nodes != b.nodes || a.node_tags != b.node_tags || a.blocks.size() != b.blocks.size() ||
      a.boundaries.size() != b.boundaries.size()) {
    return false;
  }
  for (std::size_t k = 0; k < a.blocks.size(); ++k) {
    if (a.blocks[k].type != b.blocks[k].type ||
        a.blocks[k].connectivity != b.blocks[k].connectivity ||
        a.blocks[k].tags != b.blocks[k].tags) {
      return false;
    }
  }
  for (const auto& [name, group] : a.boundaries) {
    const auto other = b.boundaries.find(name);
    if (other == b.boundaries.end() || other->second.type != group.type ||
        other->second.connectivity != group.connectivity) {
      return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  google::protobuf::SetLogHandler(nullptr);  // no log line per string with invalid UTF-8
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  robin::protocol::MeshData message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  robin::Mesh mesh;
  try {
    mesh = robin::decode_mesh(message, "fuzz");
  } catch (const robin::InputError&) {
    return 0;  // a refused mesh: the expected outcome for most inputs
  }
  robin::Mesh again;
  try {
    again = robin::decode_mesh(robin::encode_mesh(mesh), "fuzz (round trip)");
  } catch (const robin::InputError& error) {
    std::fprintf(stderr, "%s\n", error.what());
    fail("a mesh the decoder accepted is refused after encode_mesh");
  }
  if (!same_mesh(mesh, again)) fail("encode_mesh then decode_mesh changed the mesh");
  return 0;
}
