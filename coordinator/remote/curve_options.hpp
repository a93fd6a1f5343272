#pragma once
// The coordinator's CurveZMQ options (docs/security.md), shared by robin-coordinator and its
// --check-server mode:
//   --curve-secret-key FILE   the coordinator's key pair (a robin-keygen .secret file)
//   --curve-server-key FILE   the server's public key (a .public file); once for every server,
//                             or once per server in the order of the servers
// Both or neither: CURVE is off without them.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "curve_keys.hpp"

namespace robin {

struct CurveClientSettings {
  std::filesystem::path secret_key;                // empty: CURVE off
  std::vector<std::filesystem::path> server_keys;  // none, one, or one per server
};

/// Adds --curve-secret-key and --curve-server-key to `app`; `servers` says in the help which
/// servers the repeated --curve-server-key follows (e.g. "--subdomain").
void add_curve_client_options(CLI::App& app, CurveClientSettings& settings,
                              const std::string& servers);

/// What is wrong with the combination of the options for `server_count` servers, or "".
std::string curve_options_problem(const CurveClientSettings& settings, std::size_t server_count);

/// The client keys of each of `server_count` servers (all unset when CURVE is off), after
/// curve_options_problem() found nothing. Throws KeyFileError naming the file, or
/// std::runtime_error when libzmq has no CURVE.
std::vector<std::optional<CurveClientKeys>> load_curve_client_keys(
    const CurveClientSettings& settings, std::size_t server_count);

/// The keys of a local encrypted run (robin-run --curve): a fresh key pair shared by the local
/// servers and one for the coordinator, written into a private temporary directory (mode 0700)
/// for the servers to read at start-up, removed by remove_files() (once the servers listen)
/// and at destruction. The secret keys never leave this machine.
class EphemeralCurveKeys {
 public:
  /// Throws std::runtime_error when the directory or the keys cannot be made.
  EphemeralCurveKeys();
  ~EphemeralCurveKeys();
  EphemeralCurveKeys(const EphemeralCurveKeys&) = delete;
  EphemeralCurveKeys& operator=(const EphemeralCurveKeys&) = delete;

  /// robin-subdomain's options: --curve-secret-key FILE --curve-allow FILE (the coordinator).
  std::vector<std::string> server_arguments() const;
  /// What the coordinator uses with every local server.
  const CurveClientKeys& client_keys() const { return client_keys_; }
  /// Removes the key files (the servers read them when they start); idempotent.
  void remove_files() noexcept;

 private:
  std::filesystem::path directory_;
  CurveClientKeys client_keys_;
};

}  // namespace robin
