// The CurveZMQ key files through the executables:
//  - robin-keygen --output PREFIX writes PREFIX.public and PREFIX.secret (mode 0600) that toml++
//    parses, whose public keys equal the one libzmq derives from the secret key
//    (zmq_curve_public), and refuses to replace them without --force;
//  - robin-subdomain refuses to start (exit 1, a message naming the option or the file) with
//    --curve-secret-key but no allow-list, with an allow-list but no key, and with missing,
//    malformed or wrong-length key files and allow-lists;
//  - robin-coordinator (and its --check-server mode) exits 1 naming the file for unusable key
//    files and 2 for incomplete or miscounted CURVE options.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zmq.h>

#include <toml++/toml.h>
#include <array>
#include <fstream>

#include "curve_keys.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::ProcessOutcome;
using testing::run_tool;
using testing::server_options;
using testing::TemporaryDirectory;

std::string libzmq_public_key(const std::string& secret_key) {
  std::array<char, 41> public_key{};
  EXPECT_EQ(zmq_curve_public(public_key.data(), secret_key.c_str()), 0);
  return public_key.data();
}

std::string string_value(const toml::table& table, const std::string& key) {
  const auto value = table[key].value<std::string>();
  EXPECT_TRUE(value.has_value()) << "no string " << key;
  return value.value_or("");
}

TEST(CurveKeyFiles, KeygenWritesAPairThatLibzmqConfirms) {
  const TemporaryDirectory directory("keygen");
  const auto prefix = directory.path() / "node";
  const ProcessOutcome outcome =
      run_tool("robin-keygen", {"--output", prefix.string()}, directory.path(), 30.0);
  ASSERT_EQ(outcome.exit, "exited with status 0") << outcome.errors;

  const toml::table secret_file = toml::parse_file((directory.path() / "node.secret").string());
  const toml::table public_file = toml::parse_file((directory.path() / "node.public").string());
  const std::string secret_key = string_value(secret_file, "secret-key");
  const std::string public_key = string_value(public_file, "public-key");
  EXPECT_EQ(secret_key.size(), 40u);
  EXPECT_EQ(libzmq_public_key(secret_key), public_key);
  EXPECT_EQ(string_value(secret_file, "public-key"), public_key);
  EXPECT_FALSE(public_file.contains("secret-key"));
  EXPECT_NE(outcome.output.find("public key " + public_key), std::string::npos) << outcome.output;
  struct stat status {};
  ASSERT_EQ(stat((directory.path() / "node.secret").c_str(), &status), 0);
  EXPECT_EQ(status.st_mode & 0777, 0600u);

  const ProcessOutcome again =
      run_tool("robin-keygen", {"--output", prefix.string()}, directory.path(), 30.0);
  EXPECT_EQ(again.exit, "exited with status 1");
  EXPECT_NE(again.errors.find("node.public': it exists (use --force"), std::string::npos)
      << again.errors;
  const ProcessOutcome forced =
      run_tool("robin-keygen", {"--output", prefix.string(), "--force"}, directory.path(), 30.0);
  EXPECT_EQ(forced.exit, "exited with status 0") << forced.errors;
  const toml::table replaced = toml::parse_file((directory.path() / "node.secret").string());
  EXPECT_NE(string_value(replaced, "secret-key"), secret_key);
  EXPECT_EQ(run_tool("robin-keygen", {}, directory.path(), 30.0).exit, "exited with status 2");
}

/// Starts robin-subdomain with `arguments` and returns why it stopped before listening ("" when
/// it listened).
std::string server_start_failure(const std::filesystem::path& directory,
                                 const std::vector<std::string>& arguments) {
  ServerLaunchOptions options = server_options(directory);
  options.extra_arguments = arguments;
  SubdomainServer server("lower", options);
  try {
    server.await_listening();
  } catch (const std::exception& error) {
    return error.what();
  }
  return "";
}

class CurveKeyFileErrors : public ::testing::Test {
 protected:
  CurveKeyFileErrors() : directory_("curve-key-errors") {
    write_curve_key_files(path("good"), generate_curve_key_pair(), false);
    write_curve_key_files(path("other"), generate_curve_key_pair(), false);
    const CurveKeyPair good = read_curve_secret_key_file(path("good.secret"));
    const CurveKeyPair other = read_curve_secret_key_file(path("other.secret"));
    write("short.secret", "public-key = \"" + good.public_key + "\"\nsecret-key = \"" +
                              good.secret_key.substr(0, 32) + "\"\n");
    write("mixed.secret",
          "public-key = \"" + other.public_key + "\"\nsecret-key = \"" + good.secret_key + "\"\n");
    write("garbage.secret", "this is not a key file\n");
    write("allowed", good.public_key + "\n");
    write("bad-allowed", "# one key\n" + good.public_key + "\nnot-a-key\n");
  }
  std::filesystem::path path(const std::string& name) const { return directory_.path() / name; }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
  }
  const std::filesystem::path& directory() const { return directory_.path(); }

 private:
  TemporaryDirectory directory_;
};

TEST_F(CurveKeyFileErrors, ServerRefusesToStartWithoutAnAllowListOrWithBadFiles) {
  const std::string good = path("good.secret").string(), allowed = path("allowed").string();
  struct Case {
    std::vector<std::string> arguments;
    std::string expected;
  };
  const std::vector<Case> cases{
      {{"--curve-secret-key", good},
       "--curve-secret-key needs --curve-allow FILE: without an allow-list"},
      {{"--curve-allow", allowed}, "--curve-allow needs --curve-secret-key FILE"},
      {{"--curve-secret-key", path("absent.secret").string(), "--curve-allow", allowed},
       "secret key file '" + path("absent.secret").string() + "' does not exist"},
      {{"--curve-secret-key", path("short.secret").string(), "--curve-allow", allowed},
       "'" + path("short.secret").string() + "', line 2: secret-key has 32 characters"},
      {{"--curve-secret-key", path("mixed.secret").string(), "--curve-allow", allowed},
       "its public-key does not belong to its secret-key"},
      {{"--curve-secret-key", path("garbage.secret").string(), "--curve-allow", allowed},
       "'" + path("garbage.secret").string() + "', line 1: not a key file"},
      {{"--curve-secret-key", good, "--curve-allow", path("bad-allowed").string()},
       "allow-list '" + path("bad-allowed").string() + "', line 3: the key 'not-a-key'"},
  };
  for (const Case& test : cases) {
    const std::string failure = server_start_failure(directory(), test.arguments);
    EXPECT_NE(failure.find("exited with status 1"), std::string::npos) << failure;
    EXPECT_NE(failure.find(test.expected), std::string::npos) << failure;
  }
  EXPECT_EQ(
      server_start_failure(directory(), {"--curve-secret-key", good, "--curve-allow", allowed}),
      "");
}

TEST_F(CurveKeyFileErrors, CoordinatorNamesTheUnusableFile) {
  const std::string case_file = example("two_blocks.toml").string();
  const auto coordinator = [&](const std::vector<std::string>& curve) {
    std::vector<std::string> arguments{
        case_file,           "--output",    path("out").string(), "--subdomain",
        "tcp://127.0.0.1:1", "--subdomain", "tcp://127.0.0.1:2"};
    arguments.insert(arguments.end(), curve.begin(), curve.end());
    return run_tool("robin-coordinator", arguments, directory(), 30.0);
  };
  const std::string good = path("good.secret").string(), server = path("other.public").string();

  const ProcessOutcome short_key = coordinator(
      {"--curve-secret-key", path("short.secret").string(), "--curve-server-key", server});
  EXPECT_EQ(short_key.exit, "exited with status 1");
  EXPECT_NE(short_key.errors.find("'" + path("short.secret").string() +
                                  "', line 2: secret-key has 32 characters"),
            std::string::npos)
      << short_key.errors;

  const ProcessOutcome missing_server_key = coordinator(
      {"--curve-secret-key", good, "--curve-server-key", path("absent.public").string()});
  EXPECT_EQ(missing_server_key.exit, "exited with status 1");
  EXPECT_NE(missing_server_key.errors.find("public key file '" + path("absent.public").string() +
                                           "' does not exist"),
            std::string::npos)
      << missing_server_key.errors;

  const ProcessOutcome no_server_key = coordinator({"--curve-secret-key", good});
  EXPECT_EQ(no_server_key.exit, "exited with status 2");
  EXPECT_NE(no_server_key.errors.find("--curve-secret-key needs --curve-server-key"),
            std::string::npos)
      << no_server_key.errors;

  const ProcessOutcome three_keys =
      coordinator({"--curve-secret-key", good, "--curve-server-key", server, "--curve-server-key",
                   server, "--curve-server-key", server});
  EXPECT_EQ(three_keys.exit, "exited with status 2");
  EXPECT_NE(three_keys.errors.find("once (for every server) or 2 times"), std::string::npos)
      << three_keys.errors;

  const ProcessOutcome checker =
      run_tool("robin-coordinator",
               {"--check-server", "tcp://127.0.0.1:1", "--curve-secret-key",
                path("garbage.secret").string(), "--curve-server-key", server},
               directory(), 30.0);
  EXPECT_EQ(checker.exit, "exited with status 1");
  EXPECT_NE(checker.errors.find(path("garbage.secret").string()), std::string::npos)
      << checker.errors;
}

}  // namespace
}  // namespace robin
