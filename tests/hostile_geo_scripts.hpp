#pragma once
// The Gmsh script attacks of issue 11 that a 1.x coordinator could send in
// SetupBody.mesh_content: each is a piece of .geo to append to a valid script. Every one of them
// is live: run by Gmsh 4 (`gmsh -0 attack.geo`), the command ones create the witness file and
// the reading ones print a line of /etc/passwd or the script's directory. Five bypassed the
// keyword filter of the 1.x servers (refused words hidden from its tokenizer by a backslash in
// a double-quoted string, a single-quoted string holding '"', '/*' or '//', a NUL in a //
// comment, where Gmsh's comment ends).

#include <filesystem>
#include <string>
#include <vector>

namespace robin::testing {

struct HostileGeoScript {
  std::string label;
  std::string text;  // .geo statements (may hold a NUL byte)
};

/// The attacks; the command ones would run `touch <witness>`.
inline std::vector<HostileGeoScript> hostile_geo_scripts(const std::filesystem::path& witness) {
  const std::string touch = "SystemCall \"touch " + witness.string() + "\";";
  return {{"SystemCall", "\n" + touch + "\n"},
          {"ExternalProcess", "\nField[1] = ExternalProcess;\nField[1].CommandLine = \"touch " +
                                  witness.string() + "\";\nBackground Field = 1;\n"},
          {"backslash in a double-quoted string", "\ns = \"a\\\"; " + touch + " // \"\n"},
          {"single-quoted 'a\"'", "\nx = 'a\"';\n" + touch + "\n// \"\n"},
          {"single-quoted '/*'", "\nx = '/*';\n" + touch + "\nx = '*/';\n"},
          {"single-quoted '//'", "\nx = '//'; " + touch + "\n"},
          {"NUL in a // comment", "\n// comment" + std::string(1, '\0') + " " + touch + "\n"},
          {"ListFromFile /etc/passwd",
           "\nx[] = ListFromFile(\"/etc/passwd\");\nError(\"leak %g\", x[0]);\n"},
          {"CurrentDirectory", "\nError(StrCat(\"cwd \", CurrentDirectory));\n"}};
}

}  // namespace robin::testing
