// libFuzzer harness: the case-file reader. Every input is written as the text of a case file,
// <tmp>/case.toml, and read with robin::read_case_file. Only robin::InputError (a refused case
// file, with its message) may leave it; any other exception, a crash, a leak or undefined
// behaviour is a bug. The temporary directory is created once and holds empty files under the
// mesh names the seed cases use (meshes/* as in examples/, and the *.geo and *.msh of
// tests/data/), so that read_case_file, which checks that the mesh files exist but does not
// read them, gets past that check and on to the remaining keys.

#include <stdlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "coupling/case_file.hpp"
#include "numerics/errors.hpp"

namespace {

namespace fs = std::filesystem;

struct FuzzDirectory {
  fs::path root;
  fs::path case_file;

  FuzzDirectory() {
    std::string pattern = (fs::temp_directory_path() / "robin-fuzz-case-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("robin-fuzz-case-file: mkdtemp");
      std::abort();
    }
    root = pattern;
    case_file = root / "case.toml";
    // Empty stand-ins named like the meshes of the seed cases: examples/meshes/* as meshes/*,
    // tests/data/*.geo|msh in the case file's own directory.
    const fs::path source(ROBIN_SOURCE_DIR);
    fs::create_directories(root / "meshes");
    const std::pair<fs::path, fs::path> folders[] = {{source / "examples/meshes", root / "meshes"},
                                                     {source / "tests/data", root}};
    for (const auto& [folder, target] : folders) {
      for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
        const fs::path extension = entry.path().extension();
        if (extension == ".geo" || extension == ".msh") {
          std::ofstream(target / entry.path().filename()).flush();
        }
      }
    }
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
  const fs::path& path = fuzz_directory().case_file;
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!file) {
      std::perror("robin-fuzz-case-file: cannot write the case file");
      std::abort();
    }
  }
  try {
    const robin::CaseDefinition definition = robin::read_case_file(path);
    (void)definition;
  } catch (const robin::InputError&) {
    // A refused case file: the expected outcome for most inputs.
  }
  return 0;
}
