#pragma once
// Overrides of case-file keys from the command line, for parameter sweeps:
//   --set coupling.tolerance=1e-10 --set 'body[2].material.young=2e5'
// (docs/case-format.md, "Overrides").
//
// An override is KEY=VALUE, split at the first '='. KEY is a key path as the case reader's
// messages name keys: names joined by '.', each followed by any number of 1-based indices
// [N] into an array ("body[2].dirichlet[1].y", "body[1].material.voigt[1][2]"); names are
// bare TOML keys (letters, digits, '_' and '-'). VALUE is a TOML value (1e-10, 2, true,
// "text", [0.0, -1.0], { R = 5.0 }); text that is not a TOML value and does not start with
// a quote, '[' or '{' is taken as a string, so that `coupling.acceleration=aitken` works.
//
// The overrides are applied in order to the parsed document before it is interpreted, so that
// every check of the case reader applies to the overridden values: a key the schema does not
// know is refused as an unknown key of the file is, a value of the wrong type or range as in
// the file. A key absent from the file is added (with the tables on its path); an index must
// name an existing element (overrides do not add [[body.dirichlet]] entries). Messages about
// an overridden value name the override instead of a line of the file:
//   --set coupling.tolerance=abc: coupling.tolerance: expected a number, found a string

#include <toml++/toml.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace robin {

/// One step of an override's key path: a key, then indices into the array it names.
struct OverrideStep {
  std::string key;
  std::vector<int> indices;  // 1-based
};

/// An override as given ("body[2].material.young=2e5"), its key path and its value text.
struct CaseOverride {
  std::string text;
  std::vector<OverrideStep> path;
  std::string value;
};

/// "--set TEXT", how messages name an override.
std::string override_label(const std::string& text);

/// Parses KEY=VALUE (the value is not interpreted yet). Throws InputError
/// "--set TEXT: problem" when there is no '=' or KEY is not a key path.
CaseOverride parse_case_override(const std::string& text);

/// Lines of the document that hold overridden values, mapped to the overrides' labels
/// ("--set coupling.tolerance=abc"); CaseContext::prefix names the override for them.
using OverrideLines = std::map<int, std::string>;

/// Applies `overrides` in order to `document`, the parsed case file `file`. Each override's
/// value (and each table it creates) is recorded at a line past the file's last, distinct per
/// override; the returned map names them (nullptr when there are no overrides). Throws
/// InputError "--set TEXT: problem" for a malformed override, a value that is not one TOML
/// value, or a path through something that is not a table or array or an index beyond its
/// array.
std::shared_ptr<const OverrideLines> apply_case_overrides(
    toml::table& document, const std::filesystem::path& file,
    const std::vector<std::string>& overrides);

/// Adds the repeatable option --set KEY=VALUE to `app` (robin-run, robin-coordinator and
/// robin-monolithic), collected into `overrides`; a malformed KEY=VALUE is a command-line error.
void add_override_option(CLI::App& app, std::vector<std::string>& overrides);

/// `message`, an error about the case read with `overrides`, followed by the list of overrides
/// when it does not name one already (e.g. a material that the file and an override define
/// together). Unchanged without overrides.
std::string mention_overrides(const std::string& message,
                              const std::vector<std::string>& overrides);

}  // namespace robin
