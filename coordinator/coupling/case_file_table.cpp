#include "coupling/case_file_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "numerics/errors.hpp"

namespace robin {

namespace {

std::string type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a floating-point number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    case toml::node_type::none:
      break;
  }
  return "nothing";
}

std::string join(const std::vector<std::string>& words) {
  std::string joined;
  for (const auto& word : words) joined += (joined.empty() ? "" : ", ") + word;
  return joined;
}

std::string join_path(const std::string& path, std::string_view key) {
  if (path.empty()) return std::string(key);
  if (key.empty()) return path;
  return path + "." + std::string(key);
}

}  // namespace

int line_of(const toml::node& node) {
  return static_cast<int>(node.source().begin.line);
}

std::string CaseContext::prefix(int line) const {
  std::string text = file;
  if (override_lines && override_lines->count(line) != 0) {
    text = override_lines->at(line);  // a value given on the command line
  } else if (line > 0) {
    text.append(":").append(std::to_string(line));
  }
  if (!body.empty()) text.append(": body '").append(body).append("'");
  return text;
}

CheckedTable::CheckedTable(const toml::table& table, std::string path, CaseContext context,
                           std::vector<std::string> allowed)
    : table_(table), path_(std::move(path)), context_(std::move(context)) {
  const toml::key* first_unknown = nullptr;
  for (const auto& [key, value] : table_) {
    if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
    if (first_unknown == nullptr || key.source().begin.line < first_unknown->source().begin.line) {
      first_unknown = &key;
    }
  }
  if (first_unknown == nullptr) return;
  std::string message = context_.prefix(static_cast<int>(first_unknown->source().begin.line)) +
                        ": unknown key '" + join_path(path_, first_unknown->str()) + "'";
  message +=
      allowed.empty() ? " (this table takes no keys)" : " (expected one of: " + join(allowed) + ")";
  throw InputError(message);
}

CheckedTable::CheckedTable(const toml::table& table, std::string path, CaseContext context)
    : table_(table), path_(std::move(path)), context_(std::move(context)) {}

std::string CheckedTable::field(std::string_view key) const {
  return join_path(path_, key);
}

int CheckedTable::line() const {
  return line_of(table_);
}

int CheckedTable::line(std::string_view key) const {
  const toml::node* node = table_.get(key);
  const int value_line = node != nullptr ? line_of(*node) : 0;
  return value_line > 0 ? value_line : line();
}

std::string CheckedTable::location(std::string_view key) const {
  return context_.prefix(line(key));
}

void CheckedTable::fail(std::string_view key, const std::string& problem) const {
  throw InputError(location(key) + ": " + field(key) + ": " + problem);
}

void CheckedTable::fail_type(std::string_view key, const toml::node& node,
                             std::string_view expected) const {
  fail(key, "expected " + std::string(expected) + ", found " + type_name(node));
}

const toml::node& CheckedTable::required(std::string_view key) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) fail(key, "missing required key");
  return *node;
}

double CheckedTable::checked_number(std::string_view key, const toml::node& node) const {
  double value = 0.0;
  if (const auto* integer = node.as_integer()) {
    value = static_cast<double>(integer->get());
  } else if (const auto* floating = node.as_floating_point()) {
    value = floating->get();
  } else {
    fail_type(key, node, "a number");
  }
  if (!std::isfinite(value)) fail(key, "must be a finite number");
  return value;
}

std::optional<double> CheckedTable::optional_number(std::string_view key) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  return checked_number(key, *node);
}

double CheckedTable::number(std::string_view key) const {
  return checked_number(key, required(key));
}

std::optional<int> CheckedTable::optional_integer(std::string_view key) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  const auto* integer = node->as_integer();
  if (integer == nullptr) fail_type(key, *node, "an integer");
  const std::int64_t value = integer->get();
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
    fail(key, "integer " + std::to_string(value) + " is out of range");
  }
  return static_cast<int>(value);
}

std::optional<bool> CheckedTable::optional_boolean(std::string_view key) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  const auto* boolean = node->as_boolean();
  if (boolean == nullptr) fail_type(key, *node, "true or false");
  return boolean->get();
}

std::optional<std::string> CheckedTable::optional_string(std::string_view key) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  const auto* text = node->as_string();
  if (text == nullptr) fail_type(key, *node, "a string");
  return text->get();
}

std::string CheckedTable::string(std::string_view key) const {
  const toml::node& node = required(key);
  const auto* text = node.as_string();
  if (text == nullptr) fail_type(key, node, "a string");
  return text->get();
}

std::optional<std::string> CheckedTable::optional_choice(
    std::string_view key, const std::vector<std::string>& choices) const {
  std::optional<std::string> value = optional_string(key);
  if (value && std::find(choices.begin(), choices.end(), *value) == choices.end()) {
    fail(key, "'" + *value + "' is not one of: " + join(choices));
  }
  return value;
}

std::array<std::string, 2> CheckedTable::string_pair(std::string_view key) const {
  const toml::node& node = required(key);
  const auto* array = node.as_array();
  if (array == nullptr || array->size() != 2) fail(key, "expected an array of two strings");
  std::array<std::string, 2> pair;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto value = array->get(i)->value<std::string>();
    if (!value || value->empty()) fail(key, "expected an array of two non-empty strings");
    pair[i] = *value;
  }
  return pair;
}

namespace {

const std::array<std::string, 7> count_words{"zero", "one", "two", "three", "four", "five", "six"};

/// "two" for 2: the sizes of case-file vectors and matrices are at most six.
std::string count_word(int count) {
  return count >= 0 && count < static_cast<int>(count_words.size())
             ? count_words[static_cast<std::size_t>(count)]
             : std::to_string(count);
}

}  // namespace

std::optional<Eigen::VectorXd> CheckedTable::optional_vector(std::string_view key, int size) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  const auto* array = node->as_array();
  if (array == nullptr || array->size() != static_cast<std::size_t>(size)) {
    fail(key, "expected an array of " + count_word(size) + " numbers " +
                  (size == 3 ? "[x, y, z]" : "[x, y]"));
  }
  Eigen::VectorXd vector(size);
  for (int i = 0; i < size; ++i) vector(i) = checked_number(key, *array->get(i));
  return vector;
}

std::optional<Eigen::MatrixXd> CheckedTable::optional_matrix(std::string_view key, int size) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  const std::string shape = "expected " + count_word(size) + " rows of " + count_word(size) +
                            " numbers" +
                            (size == 3 ? " [[a, b, c], [d, e, f], [g, h, i]]" : " (by rows)");
  const auto* rows = node->as_array();
  if (rows == nullptr || rows->size() != static_cast<std::size_t>(size)) fail(key, shape);
  Eigen::MatrixXd matrix(size, size);
  for (int row = 0; row < size; ++row) {
    const auto* entries = rows->get(static_cast<std::size_t>(row))->as_array();
    if (entries == nullptr || entries->size() != static_cast<std::size_t>(size)) fail(key, shape);
    for (int column = 0; column < size; ++column) {
      matrix(row, column) = checked_number(key, *entries->get(static_cast<std::size_t>(column)));
    }
  }
  return matrix;
}

std::map<std::string, double> CheckedTable::number_map(std::string_view key) const {
  std::map<std::string, double> numbers;
  const toml::node* node = table_.get(key);
  if (node == nullptr) return numbers;
  const auto* table = node->as_table();
  if (table == nullptr) fail_type(key, *node, "a table of numbers such as { R = 50.0 }");
  const CheckedTable entries(*table, field(key), context_);
  for (const auto& [name, value] : *table) {
    numbers[std::string(name.str())] = entries.checked_number(name.str(), value);
  }
  return numbers;
}

std::optional<CheckedTable> CheckedTable::optional_table(std::string_view key,
                                                         std::vector<std::string> allowed) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::nullopt;
  const auto* table = node->as_table();
  if (table == nullptr) fail_type(key, *node, "a table");
  return CheckedTable(*table, field(key), context_, std::move(allowed));
}

CheckedTable CheckedTable::table(std::string_view key, std::vector<std::string> allowed) const {
  std::optional<CheckedTable> table = optional_table(key, std::move(allowed));
  if (!table) fail(key, "missing required table");
  return *table;
}

std::vector<TableEntry> CheckedTable::array_of_tables(std::string_view key) const {
  std::vector<TableEntry> entries;
  const toml::node* node = table_.get(key);
  if (node == nullptr) return entries;
  const auto* array = node->as_array();
  if (array == nullptr) {
    fail(key, "expected an array of tables ([[" + field(key) + "]]), found " + type_name(*node));
  }
  for (std::size_t i = 0; i < array->size(); ++i) {
    const std::string path = field(key) + "[" + std::to_string(i + 1) + "]";
    const auto* table = array->get(i)->as_table();
    if (table == nullptr) fail(key, path + " is " + type_name(*array->get(i)) + ", not a table");
    entries.push_back({table, path});
  }
  return entries;
}

}  // namespace robin
