// robin-keygen --output PREFIX [--force]
// Generates a CurveZMQ key pair (zmq_curve_keypair) for the encrypted transport
// (docs/security.md) and writes PREFIX.public (the public key: give it to the peers) and
// PREFIX.secret (public and secret key, mode 0600: keep it). Prints the public key.
// Exit codes: 0 written (or --help, --version); 1 CURVE unavailable or a file cannot be written
// (or exists without --force); 2 bad command line.

#include <iostream>

#include "command_line.hpp"
#include "curve_keys.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "robin-keygen: writes a CurveZMQ key pair for robin-subdomain and robin-coordinator "
      "(docs/security.md)"};
  std::filesystem::path prefix;
  bool force = false;
  app.add_option("--output,-o", prefix,
                 "writes PREFIX.public (shareable) and PREFIX.secret (mode 0600, keep it secret)")
      ->type_name("PREFIX")
      ->required();
  app.add_flag("--force", force, "replace existing key files");
  app.footer(
      "Exit codes: 0 written; 1 CURVE unavailable or a file cannot be written; 2 bad command "
      "line.");
  robin::add_version_option(app, "robin-keygen");
  if (const auto code = robin::parse_command_line(app, argc, argv)) return *code;
  try {
    if (!robin::curve_available()) {
      throw std::runtime_error("this libzmq is built without CURVE (zmq_has(\"curve\") is false)");
    }
    const robin::CurveKeyPair pair = robin::generate_curve_key_pair();
    robin::write_curve_key_files(prefix, pair, force);
    std::cout << "wrote " << robin::public_key_file(prefix).string() << " and "
              << robin::secret_key_file(prefix).string() << " (mode 0600)\npublic key "
              << pair.public_key << "\n";
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "robin-keygen: " << error.what() << "\n";
    return 1;
  }
}
