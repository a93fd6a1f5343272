// libFuzzer harness: the .msh file reader of robin-subdomain. Every input is written as a Gmsh
// mesh file, <tmp>/fuzz.msh, and read with robin::read_mesh_file_in_child (what
// SetupBody.mesh_path goes through: read_gmsh_mesh in robin-mesh-reader, a child process, the mesh
// sent back through a pipe), then checked with robin::check_element_validity as the server does.
// Only robin::InputError (a refused file, with its message) may leave it; any other exception,
// a crash, a leak or undefined behaviour of this process is a bug. A crash of Gmsh in the child
// is a refusal ("the mesh reader (Gmsh) crashed ..."): Gmsh 4.8 crashes on some malformed
// files, which is why the server reads them in a child. Coverage feedback comes from this
// process only (the pipe decoding and the validity check), not from the reader in the child;
// a sanitizer report in the child still shows in the output, which the smoke test watches.

#include <stdlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "numerics/errors.hpp"
#include "numerics/mesh_validity.hpp"
#include "server/mesh_file_reader.hpp"

namespace {

namespace fs = std::filesystem;

/// A temporary directory for the input file, created once and removed at a normal exit.
struct FuzzDirectory {
  fs::path root;
  fs::path mesh_file;

  FuzzDirectory() {
    std::string pattern = (fs::temp_directory_path() / "robin-fuzz-msh-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("robin-fuzz-mesh-file: mkdtemp");
      std::abort();
    }
    root = pattern;
    mesh_file = root / "fuzz.msh";
  }
  ~FuzzDirectory() {
    std::error_code ignored;
    fs::remove_all(root, ignored);
  }
};

FuzzDirectory& fuzz_directory() {
  static FuzzDirectory directory;
  return directory;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz_directory();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path& path = fuzz_directory().mesh_file;
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!file) {
      std::perror("robin-fuzz-mesh-file: cannot write the mesh file");
      std::abort();
    }
  }
  try {
    const robin::Mesh mesh = robin::read_mesh_file_in_child(path, ROBIN_MESH_READER);
    robin::check_element_validity(mesh, "fuzz.msh");
  } catch (const robin::InputError&) {
    // A refused file: the expected outcome for most inputs.
  }
  return 0;
}
