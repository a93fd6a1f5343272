#include "curve_keys.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zmq.h>

#include <toml++/toml.h>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

namespace robin {

namespace {

const std::string public_key_name = "public-key";
const std::string secret_key_name = "secret-key";

std::string quoted(const std::filesystem::path& path) {
  std::string text = path.string();
  text.insert(text.begin(), '\'');
  text.push_back('\'');
  return text;
}

/// The text of a TOML key file, checked for unknown keys and string values.
toml::table parse_key_file(const std::filesystem::path& path, const std::string& what,
                           const std::vector<std::string>& allowed) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw KeyFileError(
        what + " " + quoted(path) +
        (std::filesystem::exists(path, error) ? " is not a regular file" : " does not exist"));
  }
  if (std::ifstream probe(path); !probe) {
    throw KeyFileError(what + " " + quoted(path) + " cannot be read: " + std::strerror(errno));
  }
  toml::table table;
  try {
    table = toml::parse_file(path.string());
  } catch (const toml::parse_error& parse_error) {
    throw KeyFileError(what + " " + quoted(path) + ", line " +
                       std::to_string(parse_error.source().begin.line) +
                       ": not a key file (expected lines like public-key = \"...\"): " +
                       std::string(parse_error.description()));
  }
  for (const auto& [key, value] : table) {
    const std::string name(key.str());
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
      throw KeyFileError(what + " " + quoted(path) + ", line " +
                         std::to_string(key.source().begin.line) + ": unknown key '" + name +
                         "' (a key file holds public-key and, in a .secret file, secret-key)");
    }
    if (!value.is_string()) {
      throw KeyFileError(what + " " + quoted(path) + ", line " +
                         std::to_string(key.source().begin.line) + ": " + name +
                         " must be a string (\"...\")");
    }
  }
  return table;
}

/// The Z85 key `name` of a parsed key file, checked.
std::string key_of(const toml::table& table, const std::string& name,
                   const std::filesystem::path& path, const std::string& what) {
  const auto* node = table.get(name);
  if (node == nullptr) {
    throw KeyFileError(what + " " + quoted(path) + " has no " + name + " = \"...\" line");
  }
  std::string key = node->as_string()->get();
  if (const std::string problem = z85_key_problem(key); !problem.empty()) {
    throw KeyFileError(what + " " + quoted(path) + ", line " +
                       std::to_string(node->source().begin.line) + ": " + name + " " + problem);
  }
  return key;
}

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  const auto last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

/// "" when `rest` (what follows a key on its line) is empty or a comment; else the problem.
void check_line_rest(const std::string& rest) {
  if (!rest.empty() && rest.front() != '#') {
    throw std::invalid_argument("unexpected text '" + rest + "' after the key");
  }
}

/// The key of a line public-key = "KEY" (a .public file's line).
std::string quoted_key_value(const std::string& text) {
  std::string rest = trimmed(text.substr(public_key_name.size()));
  if (rest.empty() || rest.front() != '=') {
    throw std::invalid_argument("expected public-key = \"KEY\"");
  }
  rest = trimmed(rest.substr(1));
  const char quote = rest.empty() ? '\0' : rest.front();
  const auto closing = quote == '"' || quote == '\'' ? rest.find(quote, 1) : std::string::npos;
  if (closing == std::string::npos) {
    throw std::invalid_argument("expected public-key = \"KEY\" (the key in quotes)");
  }
  check_line_rest(trimmed(rest.substr(closing + 1)));
  return rest.substr(1, closing - 1);
}

/// The key on one allow-list line, or "" for a blank or comment line. A comment starts with
/// '#' at the beginning of the line or after blanks behind the key ('#' is a Z85 character, but
/// never the first of a key: a group of five characters starting with it exceeds 32 bits).
/// Throws std::invalid_argument when there is text after the key.
std::string allow_list_key(const std::string& line) {
  const std::string text = trimmed(line);
  if (text.empty() || text.front() == '#') return "";
  if (text.rfind(public_key_name, 0) == 0) return quoted_key_value(text);
  const std::string first_word = text.substr(0, text.find_first_of(" \t"));
  check_line_rest(trimmed(text.substr(first_word.size())));
  return first_word;
}

/// Writes `text` to `path` with `mode`, replacing the file only when `overwrite`.
void write_file(const std::filesystem::path& path, const std::string& text, mode_t mode,
                bool overwrite) {
  const int flags = O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | (overwrite ? 0 : O_EXCL);
  const int descriptor = ::open(path.c_str(), flags, mode);
  if (descriptor < 0) {
    const int error = errno;
    throw KeyFileError("cannot write " + quoted(path) + ": " + std::strerror(error) +
                       (error == EEXIST ? " (it exists; use --force to replace it)" : ""));
  }
  bool written = ::fchmod(descriptor, mode) == 0;
  for (std::size_t done = 0; written && done < text.size();) {
    const ssize_t count = ::write(descriptor, text.data() + done, text.size() - done);
    if (count < 0 && errno == EINTR) continue;
    written = count > 0;
    if (written) done += static_cast<std::size_t>(count);
  }
  const int error = errno;
  if (::close(descriptor) != 0 || !written) {
    throw KeyFileError("cannot write " + quoted(path) + ": " + std::strerror(error));
  }
}

}  // namespace

bool curve_available() {
  return zmq_has("curve") != 0;
}

CurveKeyPair generate_curve_key_pair() {
  std::array<char, curve_key_characters + 1> public_key{}, secret_key{};
  if (zmq_curve_keypair(public_key.data(), secret_key.data()) != 0) {
    throw std::runtime_error(std::string("cannot generate a CURVE key pair: ") +
                             zmq_strerror(zmq_errno()) +
                             " (is libzmq built with CURVE, zmq_has(\"curve\")?)");
  }
  return {public_key.data(), secret_key.data()};
}

std::string curve_public_key_of(const std::string& secret_key) {
  if (const std::string problem = z85_key_problem(secret_key); !problem.empty()) {
    throw std::invalid_argument("the secret key " + problem);
  }
  std::array<char, curve_key_characters + 1> public_key{};
  if (zmq_curve_public(public_key.data(), secret_key.c_str()) != 0) {
    throw std::invalid_argument(std::string("cannot derive the public key: ") +
                                zmq_strerror(zmq_errno()));
  }
  return public_key.data();
}

std::string z85_key_problem(const std::string& key) {
  if (key.size() != curve_key_characters) {
    return "has " + std::to_string(key.size()) + " characters, expected " +
           std::to_string(curve_key_characters) + " (a 32-byte key in Z85)";
  }
  static const std::string alphabet =
      "0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ.-:+=^!/*?&<>()[]{}@%$#";
  if (const auto bad = key.find_first_not_of(alphabet); bad != std::string::npos) {
    return "contains '" + std::string(1, key[bad]) + "' (character " + std::to_string(bad + 1) +
           "), which is not a Z85 character";
  }
  std::array<std::uint8_t, 32> decoded{};
  if (zmq_z85_decode(decoded.data(), key.c_str()) == nullptr) {
    return "is not valid Z85 (a group of five characters exceeds 32 bits)";
  }
  return "";
}

std::filesystem::path public_key_file(const std::filesystem::path& prefix) {
  return prefix.string() + ".public";
}

std::filesystem::path secret_key_file(const std::filesystem::path& prefix) {
  return prefix.string() + ".secret";
}

void write_curve_key_files(const std::filesystem::path& prefix, const CurveKeyPair& pair,
                           bool overwrite) {
  const std::filesystem::path public_path = public_key_file(prefix);
  const std::filesystem::path secret_path = secret_key_file(prefix);
  if (!overwrite) {
    for (const auto& path : {public_path, secret_path}) {
      std::error_code error;
      if (std::filesystem::exists(path, error)) {
        throw KeyFileError("cannot write " + quoted(path) +
                           ": it exists (use --force to replace it)");
      }
    }
  }
  const std::string public_line = public_key_name + " = \"" + pair.public_key + "\"\n";
  write_file(secret_path,
             "# robin-contact CurveZMQ key pair (Z85). Keep it secret: it authenticates its "
             "owner.\n" +
                 public_line + secret_key_name + " = \"" + pair.secret_key + "\"\n",
             0600, overwrite);
  write_file(public_path,
             "# robin-contact CurveZMQ public key (Z85): give it to the peers (allow-list, "
             "--curve-server-key).\n" +
                 public_line,
             0644, overwrite);
}

CurveKeyPair read_curve_secret_key_file(const std::filesystem::path& path) {
  const std::string what = "secret key file";
  const toml::table table = parse_key_file(path, what, {public_key_name, secret_key_name});
  CurveKeyPair pair;
  pair.secret_key = key_of(table, secret_key_name, path, what);
  pair.public_key = key_of(table, public_key_name, path, what);
  if (curve_public_key_of(pair.secret_key) != pair.public_key) {
    throw KeyFileError(what + " " + quoted(path) +
                       ": its public-key does not belong to its secret-key (the files of two "
                       "key pairs mixed up?)");
  }
  return pair;
}

std::string read_curve_public_key_file(const std::filesystem::path& path) {
  const std::string what = "public key file";
  const toml::table table = parse_key_file(path, what, {public_key_name, secret_key_name});
  return key_of(table, public_key_name, path, what);
}

std::vector<std::string> read_curve_allow_list(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw KeyFileError(
        "allow-list " + quoted(path) +
        (std::filesystem::exists(path, error) ? " is not a regular file" : " does not exist"));
  }
  std::ifstream file(path);
  if (!file) {
    throw KeyFileError("allow-list " + quoted(path) + " cannot be read: " + std::strerror(errno));
  }
  std::vector<std::string> keys;
  std::set<std::string> seen;
  int number = 0;
  for (std::string line; std::getline(file, line);) {
    ++number;
    const std::string where = "allow-list " + quoted(path) + ", line " + std::to_string(number);
    const std::string format =
        " (expected one client public key per line, bare or as public-key = \"...\")";
    std::string key;
    try {
      key = allow_list_key(line);
    } catch (const std::invalid_argument& problem) {
      throw KeyFileError(where + ": " + problem.what() + format);
    }
    if (key.empty()) continue;
    if (const std::string problem = z85_key_problem(key); !problem.empty()) {
      throw KeyFileError(where + ": the key '" + key + "' " + problem + format);
    }
    if (seen.insert(key).second) keys.push_back(key);
  }
  if (keys.empty()) {
    throw KeyFileError("allow-list " + quoted(path) +
                       " holds no key (one client public key per line; a server that admits "
                       "nobody is of no use)");
  }
  return keys;
}

std::string secret_key_file_permission_warning(const std::filesystem::path& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) return "";
  if ((status.st_mode & (S_IRWXG | S_IRWXO)) == 0) return "";
  std::ostringstream text;
  text << "secret key file " << quoted(path) << " is accessible by group or others (mode "
       << std::oct << (status.st_mode & 07777) << "); chmod 600 it";
  return text.str();
}

}  // namespace robin
