#pragma once
// Checked access to one table of a parsed case file (internal to case_file.cpp).
//
// Every accessor validates the type (numbers accept TOML integers and floats and must be
// finite) and throws InputError worded as
//   "FILE:LINE: body 'NAME': FIELD: problem"
// where LINE is the line of the value (of the table when the key is missing), the body part
// is present inside a [[body]] table whose name is known, and FIELD is the full key path
// ("body[2].dirichlet[1].boundary", 1-based indices).

#include <toml++/toml.h>
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace robin {

/// Who is speaking in a message: the case file as the user named it, and the body (if any).
struct CaseContext {
  std::string file;
  std::string body;  // empty outside a [[body]] table
  /// Lines that hold values of command-line overrides, and the overrides' labels
  /// (case_file_overrides.hpp): prefix() names the override instead of FILE:LINE.
  std::shared_ptr<const std::map<int, std::string>> override_lines = nullptr;
  /// "FILE:LINE: body 'NAME'" (without ":LINE" when line <= 0, without the body part when
  /// the body is unknown).
  std::string prefix(int line) const;
};

class CheckedTable;

/// One element of an array of tables, not yet checked.
struct TableEntry {
  const toml::table* table = nullptr;
  std::string path;  // "body[1]"
};

class CheckedTable {
 public:
  /// Checks that every key of `table` is in `allowed`; otherwise throws InputError for the
  /// unknown key that comes first in the file, naming its full path and the allowed keys.
  CheckedTable(const toml::table& table, std::string path, CaseContext context,
               std::vector<std::string> allowed);
  /// A table whose keys are free names (not checked).
  CheckedTable(const toml::table& table, std::string path, CaseContext context);

  const CaseContext& context() const { return context_; }
  /// Full path of `key` in the file ("solver.qp_tolerance"); the table's own path when empty.
  std::string field(std::string_view key = {}) const;
  /// Line of the table (its header, or its first character when inline); 0 when unknown.
  int line() const;
  /// Line of the value of `key`, or of the table when `key` is absent.
  int line(std::string_view key) const;
  /// "FILE:LINE: body 'NAME'" for `key` (see line(key)).
  std::string location(std::string_view key) const;
  bool contains(std::string_view key) const { return table_.contains(key); }
  /// The TOML table itself, for readers of values no accessor below covers.
  const toml::table& raw() const { return table_; }

  std::optional<double> optional_number(std::string_view key) const;
  double number(std::string_view key) const;
  std::optional<int> optional_integer(std::string_view key) const;
  std::optional<bool> optional_boolean(std::string_view key) const;
  std::optional<std::string> optional_string(std::string_view key) const;
  std::string string(std::string_view key) const;
  /// A string that must be one of `choices`.
  std::optional<std::string> optional_choice(std::string_view key,
                                             const std::vector<std::string>& choices) const;
  /// [a, b] (size 2) or [a, b, c] (size 3) of numbers.
  std::optional<Eigen::VectorXd> optional_vector(std::string_view key, int size) const;
  /// ["a", "b"] of two non-empty strings (required).
  std::array<std::string, 2> string_pair(std::string_view key) const;
  /// A size x size matrix of numbers, by rows ([[a, b, c], [d, e, f], [g, h, i]] for size 3).
  std::optional<Eigen::MatrixXd> optional_matrix(std::string_view key, int size) const;
  /// A table whose keys are free names and whose values are numbers.
  std::map<std::string, double> number_map(std::string_view key) const;

  /// The sub-table `key`, checked against `allowed`; nullopt when absent.
  std::optional<CheckedTable> optional_table(std::string_view key,
                                             std::vector<std::string> allowed) const;
  CheckedTable table(std::string_view key, std::vector<std::string> allowed) const;
  /// The elements of the array of tables `key` ([[key]] or [{...}, ...]); empty when absent.
  std::vector<TableEntry> array_of_tables(std::string_view key) const;

  /// Throws InputError "LOCATION: FIELD: problem" for `key`.
  [[noreturn]] void fail(std::string_view key, const std::string& problem) const;

 private:
  const toml::node& required(std::string_view key) const;
  [[noreturn]] void fail_type(std::string_view key, const toml::node& node,
                              std::string_view expected) const;
  double checked_number(std::string_view key, const toml::node& node) const;

  const toml::table& table_;
  std::string path_;
  CaseContext context_;
};

/// Line of a node in its file; 0 when toml++ did not record one.
int line_of(const toml::node& node);

}  // namespace robin
