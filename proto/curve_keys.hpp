#pragma once
// CurveZMQ keys of the transport (docs/security.md): key pairs, key files and allow-lists,
// shared by robin-keygen, robin-subdomain (the server) and the coordinator (the client).
//
// A key is 32 bytes, written as 40 characters of Z85 (ZeroMQ RFC 32). Key files are TOML:
//   PREFIX.public   public-key = "<40 characters>"                  (shareable)
//   PREFIX.secret   public-key = "<40 characters>"
//                   secret-key = "<40 characters>"                  (mode 0600)
// Lines starting with '#' are comments; no other keys are allowed. A secret file's public key
// must be the one its secret key determines (zmq_curve_public).
//
// An allow-list (robin-subdomain --curve-allow FILE) holds one client public key per line,
// either bare (40 characters of Z85) or as a .public file's line `public-key = "..."`, so that
// concatenated .public files are an allow-list. A line starting with '#' is a comment (no key
// starts with '#'), as is '#' after blanks behind a key ('#' is a Z85 character inside a key);
// blank lines are ignored.
//
// Every problem with a file throws KeyFileError naming the file (and the line when there is one).

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace robin {

/// A key file or allow-list that cannot be used; the message names the file.
class KeyFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The length of a key in Z85 text.
constexpr std::size_t curve_key_characters = 40;

/// A CURVE key pair in Z85 text.
struct CurveKeyPair {
  std::string public_key;
  std::string secret_key;
};

/// What a CURVE client needs: its own key pair and the server's public key (Z85 text).
struct CurveClientKeys {
  std::string server_public_key;
  CurveKeyPair client;
};

/// True when libzmq was built with CURVE (zmq_has("curve")).
bool curve_available();

/// A fresh key pair (zmq_curve_keypair). Throws std::runtime_error when CURVE is unavailable.
CurveKeyPair generate_curve_key_pair();

/// The public key that belongs to `secret_key` (zmq_curve_public). Throws std::invalid_argument
/// for a secret key that is not valid Z85 of 40 characters.
std::string curve_public_key_of(const std::string& secret_key);

/// Why `key` is not a key in Z85 text ("has 39 characters, expected 40", "contains '~', which
/// is not a Z85 character"), or "" when it is one.
std::string z85_key_problem(const std::string& key);

/// Writes PREFIX.public (mode 0644 before the umask) and PREFIX.secret (mode 0600). Existing
/// files are replaced only when `overwrite`. Throws KeyFileError naming the file.
void write_curve_key_files(const std::filesystem::path& prefix, const CurveKeyPair& pair,
                           bool overwrite);
std::filesystem::path public_key_file(const std::filesystem::path& prefix);
std::filesystem::path secret_key_file(const std::filesystem::path& prefix);

/// Reads a .secret file: both keys present, valid, and belonging together.
CurveKeyPair read_curve_secret_key_file(const std::filesystem::path& path);
/// Reads the public key of a .public file (a .secret file is accepted too: its public key).
std::string read_curve_public_key_file(const std::filesystem::path& path);
/// Reads an allow-list (see above). At least one key; duplicates are kept once.
std::vector<std::string> read_curve_allow_list(const std::filesystem::path& path);

/// A warning when the secret file at `path` can be read or written by group or others, or "".
std::string secret_key_file_permission_warning(const std::filesystem::path& path);

}  // namespace robin
