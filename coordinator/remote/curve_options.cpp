#include "remote/curve_options.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace robin {

void add_curve_client_options(CLI::App& app, CurveClientSettings& settings,
                              const std::string& servers) {
  app.add_option("--curve-secret-key", settings.secret_key,
                 "this coordinator's key pair (a robin-keygen .secret file): encrypts the "
                 "connections with CurveZMQ; needs --curve-server-key")
      ->type_name("FILE");
  app.add_option("--curve-server-key", settings.server_keys,
                 "the server's public key (a .public file); once for all servers, or once per "
                 "server in the order of " +
                     servers)
      ->type_name("FILE")
      ->allow_extra_args(false);
}

std::string curve_options_problem(const CurveClientSettings& settings, std::size_t server_count) {
  const std::size_t keys = settings.server_keys.size();
  if (settings.secret_key.empty() && keys == 0) return "";
  if (settings.secret_key.empty()) {
    return "--curve-server-key needs --curve-secret-key FILE (this coordinator's key pair, "
           "from robin-keygen)";
  }
  if (keys == 0) {
    return "--curve-secret-key needs --curve-server-key FILE (the server's public key)";
  }
  if (keys != 1 && keys != server_count) {
    return "give --curve-server-key once (for every server) or " + std::to_string(server_count) +
           " times (one per server, in order); got " + std::to_string(keys);
  }
  return "";
}

std::vector<std::optional<CurveClientKeys>> load_curve_client_keys(
    const CurveClientSettings& settings, std::size_t server_count) {
  std::vector<std::optional<CurveClientKeys>> keys(server_count);
  if (settings.secret_key.empty()) return keys;
  if (!curve_available()) {
    throw std::runtime_error("this libzmq is built without CURVE (zmq_has(\"curve\") is false)");
  }
  const CurveKeyPair client = read_curve_secret_key_file(settings.secret_key);
  for (std::size_t index = 0; index < server_count; ++index) {
    const auto& file = settings.server_keys[settings.server_keys.size() == 1 ? 0 : index];
    keys[index] = CurveClientKeys{read_curve_public_key_file(file), client};
  }
  return keys;
}

EphemeralCurveKeys::EphemeralCurveKeys() {
  std::string pattern = (std::filesystem::temp_directory_path() / "robin-curve-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {  // mode 0700
    throw std::runtime_error("cannot create a private directory for the CurveZMQ keys (" + pattern +
                             "): " + std::strerror(errno));
  }
  directory_ = pattern;
  try {
    write_curve_key_files(directory_ / "server", generate_curve_key_pair(), false);
    const CurveKeyPair coordinator = generate_curve_key_pair();
    write_curve_key_files(directory_ / "coordinator", coordinator, false);
    client_keys_ = {read_curve_public_key_file(public_key_file(directory_ / "server")),
                    coordinator};
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove_all(directory_, ignored);
    throw;
  }
}

EphemeralCurveKeys::~EphemeralCurveKeys() {
  remove_files();
}

void EphemeralCurveKeys::remove_files() noexcept {
  std::error_code ignored;
  std::filesystem::remove_all(directory_, ignored);
}

std::vector<std::string> EphemeralCurveKeys::server_arguments() const {
  return {"--curve-secret-key", secret_key_file(directory_ / "server").string(), "--curve-allow",
          public_key_file(directory_ / "coordinator").string()};
}

}  // namespace robin
