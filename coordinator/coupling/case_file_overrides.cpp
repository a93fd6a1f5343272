#include "coupling/case_file_overrides.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

#include "numerics/errors.hpp"

namespace robin {

namespace {

const char* const key_path_syntax =
    "a key path is names of letters, digits, '_' and '-' joined by '.', each followed by any "
    "number of indices [N] counted from 1, e.g. body[2].material.young";

bool is_key_character(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
}

std::vector<OverrideStep> parse_key_path(const std::string& key, const std::string& label) {
  const auto fail = [&](const std::string& problem) -> InputError {
    return InputError(label + ": '" + key + "' is not a key path (" + problem + "; " +
                      key_path_syntax + ")");
  };
  std::vector<OverrideStep> path;
  std::size_t position = 0;
  while (true) {
    OverrideStep step;
    while (position < key.size() && is_key_character(key[position])) step.key += key[position++];
    if (step.key.empty())
      throw fail("a name is missing at character " + std::to_string(position + 1));
    while (position < key.size() && key[position] == '[') {
      const std::size_t close = key.find(']', position);
      const std::string digits =
          close == std::string::npos ? "" : key.substr(position + 1, close - position - 1);
      const bool numeric = !digits.empty() && digits.size() <= 9 &&
                           digits.find_first_not_of("0123456789") == std::string::npos;
      if (!numeric || std::stoi(digits) < 1) {
        throw fail("an index must be a whole number >= 1 in brackets");
      }
      step.indices.push_back(std::stoi(digits));
      position = close + 1;
    }
    path.push_back(std::move(step));
    if (position == key.size()) return path;
    if (key[position] != '.') {
      throw fail("unexpected '" + std::string(1, key[position]) + "' at character " +
                 std::to_string(position + 1));
    }
    ++position;
  }
}

/// A TOML basic string holding `text`.
std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    const auto code = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (code < 0x20 || code == 0x7f) {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\u%04x", static_cast<unsigned>(code));
      out += escape;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string type_name(const toml::node& node) {
  std::ostringstream text;
  text << node.type();
  return text.str();
}

/// The number of the first line after the last line of `file` (toml++ counts from 1).
int first_line_after(const std::filesystem::path& file) {
  std::ifstream stream(file, std::ios::binary);
  const auto newlines =
      std::count(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>(), '\n');
  return static_cast<int>(newlines) + 2;
}

/// A document whose only key, "value", holds `value` parsed as TOML at line `line` (so that
/// its source line names the override). Text that is not a TOML value and does not start
/// like one (a quote, '[' or '{') becomes a string.
toml::table value_document(const std::string& value, int line, const std::string& label) {
  const std::string padding(static_cast<std::size_t>(line - 1), '\n');
  std::string problem;
  try {
    toml::table parsed = toml::parse(padding + "value = " + value, label);
    if (parsed.size() == 1 && parsed.contains("value")) return parsed;
    problem = "it is more than one TOML value";
  } catch (const toml::parse_error& error) {
    const bool starts_like_a_value =
        !value.empty() && std::string("\"'[{").find(value.front()) != std::string::npos;
    if (!starts_like_a_value) {
      try {
        return toml::parse(padding + "value = " + quoted(value), label);
      } catch (const toml::parse_error& string_error) {
        problem = std::string(string_error.description());
      }
    } else {
      problem = std::string(error.description());
    }
  }
  throw InputError(label + ": the value '" + value + "' is not a TOML value: " + problem);
}

toml::key key_at(const std::string& name, int line, const std::string& label) {
  toml::source_region region;
  region.begin = {static_cast<toml::source_index>(line), 1};
  region.end = region.begin;
  region.path = std::make_shared<const std::string>(label);
  return toml::key(name, std::move(region));
}

void apply_override(toml::table& document, const CaseOverride& override, int line,
                    const std::string& label) {
  const auto value_node = [&](const std::string& text, toml::table& holder) -> toml::node&& {
    holder = value_document(text, line, label);
    return std::move(*holder.get("value"));
  };
  toml::node* current = &document;
  std::string walked;
  for (std::size_t s = 0; s < override.path.size(); ++s) {
    const OverrideStep& step = override.path[s];
    const bool last_step = s + 1 == override.path.size();
    toml::table* table = current->as_table();
    if (table == nullptr) {
      throw InputError(label + ": " + walked + " is " + type_name(*current) + ", not a table");
    }
    walked += (walked.empty() ? "" : ".") + step.key;
    toml::table holder;
    if (last_step && step.indices.empty()) {
      table->insert_or_assign(key_at(step.key, line, label), value_node(override.value, holder));
      return;
    }
    toml::node* child = table->get(step.key);
    if (child == nullptr) {
      if (!step.indices.empty()) {
        throw InputError(label + ": the case file has no " + walked +
                         " (an override changes an element of an array, it does not add one)");
      }
      table->insert_or_assign(key_at(step.key, line, label), value_node("{}", holder));
      child = table->get(step.key);
    }
    for (std::size_t k = 0; k < step.indices.size(); ++k) {
      toml::array* array = child->as_array();
      if (array == nullptr) {
        throw InputError(label + ": " + walked + " is " + type_name(*child) + ", not an array");
      }
      const auto index = static_cast<std::size_t>(step.indices[k]);
      if (index > array->size()) {
        throw InputError(label + ": " + walked + "[" + std::to_string(index) +
                         "]: the case file has " + std::to_string(array->size()) +
                         " element(s) in " + walked +
                         " (an override changes an element, it does not add one)");
      }
      walked += "[" + std::to_string(index) + "]";
      if (last_step && k + 1 == step.indices.size()) {
        array->replace(array->cbegin() + static_cast<std::ptrdiff_t>(index - 1),
                       value_node(override.value, holder));
        return;
      }
      child = array->get(index - 1);
    }
    current = child;
  }
}

}  // namespace

std::string override_label(const std::string& text) {
  return "--set " + text;
}

CaseOverride parse_case_override(const std::string& text) {
  const std::string label = override_label(text);
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos) {
    throw InputError(label + ": expected KEY=VALUE, e.g. coupling.tolerance=1e-10");
  }
  CaseOverride override;
  override.text = text;
  override.path = parse_key_path(text.substr(0, equals), label);
  override.value = text.substr(equals + 1);
  return override;
}

std::shared_ptr<const OverrideLines> apply_case_overrides(
    toml::table& document, const std::filesystem::path& file,
    const std::vector<std::string>& overrides) {
  if (overrides.empty()) return nullptr;
  auto lines = std::make_shared<OverrideLines>();
  int line = first_line_after(file);
  for (const std::string& text : overrides) {
    const std::string label = override_label(text);
    apply_override(document, parse_case_override(text), line, label);
    (*lines)[line] = label;
    ++line;
  }
  return lines;
}

void add_override_option(CLI::App& app, std::vector<std::string>& overrides) {
  app.add_option("--set", overrides,
                 "override a key of the case file, e.g. --set coupling.tolerance=1e-10 --set "
                 "'body[2].material.young=2e5' (KEY as in the case file's messages, VALUE a TOML "
                 "value; a bare word is a string); repeatable, applied in order "
                 "(docs/case-format.md, \"Overrides\")")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false)
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            try {
              parse_case_override(text);
              return "";
            } catch (const InputError& error) {  // CLI11 names the option: leave out the label
              const std::string message = error.what();
              const std::string label = override_label(text) + ": ";
              return "'" + text + "': " +
                     (message.rfind(label, 0) == 0 ? message.substr(label.size()) : message);
            }
          },
          ""));  // the type name says KEY=VALUE already
}

std::string mention_overrides(const std::string& message,
                              const std::vector<std::string>& overrides) {
  if (overrides.empty() || message.find("--set ") != std::string::npos) return message;
  std::string list;
  for (const std::string& text : overrides)
    list += (list.empty() ? "" : ", ") + override_label(text);
  return message + " (with the overrides " + list + ")";
}

}  // namespace robin
