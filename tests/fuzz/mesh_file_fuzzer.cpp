// libFuzzer harness: the .msh file reader of robin-subdomain and the tools. Every input is the
// contents of a Gmsh mesh file, read with robin::parse_msh_file (msh_file.hpp: what
// SetupBody.mesh_path .msh files and the tools' .msh files go through, in-process, read_msh_file
// without the file) and checked with robin::check_element_validity as the server does. Only
// robin::InputError (a refused file, with its message) may leave it; any other exception, a
// crash, a leak, an allocation beyond libFuzzer's limit (a count believed without checking the
// bytes left) or undefined behaviour is a bug.

#include <cstddef>
#include <cstdint>
#include <string>

#include "numerics/errors.hpp"
#include "numerics/mesh_validity.hpp"
#include "numerics/msh_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const robin::Mesh mesh = robin::parse_msh_file(bytes, "fuzz.msh");
    robin::check_element_validity(mesh, "fuzz.msh");
  } catch (const robin::InputError&) {
    // A refused file: the expected outcome for most inputs.
  }
  return 0;
}
