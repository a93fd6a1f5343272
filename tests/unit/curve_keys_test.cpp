// CurveZMQ key files and allow-lists (proto/curve_keys.hpp): a written key pair reads back and
// its public key is the one libzmq derives from its secret key (zmq_curve_public, independent
// of the reader); the secret file has mode 0600; every malformed file (missing, TOML syntax,
// unknown key, wrong length, non-Z85 character, mixed-up pair, empty allow-list) is refused
// with a message naming the file and, where there is one, the line.

#include "curve_keys.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zmq.h>

#include <array>
#include <atomic>
#include <fstream>

namespace robin {
namespace {

class CurveKeys : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    directory_ = std::filesystem::temp_directory_path() /
                 ("robin-curve-keys-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(directory_);
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = directory_ / name;
    std::ofstream(path) << text;
    return path;
  }

  /// The message of the KeyFileError `action` throws; fails the test when it throws none.
  template <typename Action>
  static std::string error_of(Action action) {
    try {
      action();
    } catch (const KeyFileError& error) {
      return error.what();
    }
    ADD_FAILURE() << "no KeyFileError";
    return "";
  }

  std::filesystem::path directory_;
};

/// The public key libzmq derives from `secret_key`, without the code under test.
std::string libzmq_public_key(const std::string& secret_key) {
  std::array<char, 41> public_key{};
  EXPECT_EQ(zmq_curve_public(public_key.data(), secret_key.c_str()), 0);
  return public_key.data();
}

TEST_F(CurveKeys, WrittenPairReadsBackAndBelongsTogether) {
  ASSERT_TRUE(curve_available());
  const CurveKeyPair pair = generate_curve_key_pair();
  EXPECT_EQ(pair.public_key.size(), 40u);
  EXPECT_EQ(libzmq_public_key(pair.secret_key), pair.public_key);
  write_curve_key_files(directory_ / "node", pair, false);

  const CurveKeyPair read = read_curve_secret_key_file(directory_ / "node.secret");
  EXPECT_EQ(read.public_key, pair.public_key);
  EXPECT_EQ(read.secret_key, pair.secret_key);
  EXPECT_EQ(read_curve_public_key_file(directory_ / "node.public"), pair.public_key);
  EXPECT_EQ(read_curve_public_key_file(directory_ / "node.secret"), pair.public_key);
  EXPECT_EQ(read_curve_allow_list(directory_ / "node.public"),
            std::vector<std::string>{pair.public_key});

  struct stat status {};
  ASSERT_EQ(stat((directory_ / "node.secret").c_str(), &status), 0);
  EXPECT_EQ(status.st_mode & 0777, 0600u);
  EXPECT_EQ(secret_key_file_permission_warning(directory_ / "node.secret"), "");
  std::ifstream public_file(directory_ / "node.public");
  const std::string public_text((std::istreambuf_iterator<char>(public_file)),
                                std::istreambuf_iterator<char>());
  EXPECT_EQ(public_text.find(pair.secret_key), std::string::npos);
  EXPECT_EQ(public_text.find("secret-key"), std::string::npos);
}

TEST_F(CurveKeys, ExistingFilesAreReplacedOnlyOnRequest) {
  write_curve_key_files(directory_ / "node", generate_curve_key_pair(), false);
  const std::string message = error_of(
      [&] { write_curve_key_files(directory_ / "node", generate_curve_key_pair(), false); });
  EXPECT_NE(message.find("node.public"), std::string::npos) << message;
  EXPECT_NE(message.find("exists"), std::string::npos) << message;
  const CurveKeyPair second = generate_curve_key_pair();
  write_curve_key_files(directory_ / "node", second, true);
  EXPECT_EQ(read_curve_secret_key_file(directory_ / "node.secret").secret_key, second.secret_key);
}

TEST_F(CurveKeys, LooseModeOfASecretFileIsWarnedAbout) {
  write_curve_key_files(directory_ / "node", generate_curve_key_pair(), false);
  ASSERT_EQ(chmod((directory_ / "node.secret").c_str(), 0644), 0);
  const std::string warning = secret_key_file_permission_warning(directory_ / "node.secret");
  EXPECT_NE(warning.find("node.secret"), std::string::npos) << warning;
  EXPECT_NE(warning.find("644"), std::string::npos) << warning;
}

TEST_F(CurveKeys, MalformedKeyFilesAreRefusedNamingFileAndLine) {
  const CurveKeyPair pair = generate_curve_key_pair();
  const CurveKeyPair other = generate_curve_key_pair();
  struct Case {
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases{
      {"public-key = \"" + pair.public_key + "\"\n", "has no secret-key"},
      {"public-key = \"" + pair.public_key.substr(1) + "\"\nsecret-key = \"" + pair.secret_key +
           "\"\n",
       "line 1: public-key has 39 characters, expected 40"},
      {"public-key = \"" + pair.public_key + "\"\nsecret-key = \"" + pair.secret_key + "xy\"\n",
       "line 2: secret-key has 42 characters"},
      {"public-key = \"" + pair.public_key + "\"\nsecret-key = \"" + pair.secret_key.substr(1) +
           "~\"\n",
       "line 2: secret-key contains '~' (character 40), which is not a Z85 character"},
      {"public-key = \"" + other.public_key + "\"\nsecret-key = \"" + pair.secret_key + "\"\n",
       "does not belong to its secret-key"},
      {"public-key = \"" + pair.public_key + "\"\nsecret_key = \"" + pair.secret_key + "\"\n",
       "line 2: unknown key 'secret_key'"},
      // An unquoted key is a TOML syntax error only when it does not begin like a TOML value: a
      // random key such as "12345#..." would parse as the integer 12345 and a comment. The
      // public key of ZeroMQ's CurveZMQ test vector begins with a letter and has no '#'.
      {"public-key = Yne@$w-vo<fVvi]a<NY6T1ed:M$fCG*[IaLV{hID\n", "line 1: not a key file"},
      {"public-key = 42\nsecret-key = \"" + pair.secret_key + "\"\n",
       "line 1: public-key must be a string"},
  };
  for (std::size_t index = 0; index < cases.size(); ++index) {
    const auto path = write("case" + std::to_string(index) + ".secret", cases[index].text);
    const std::string message = error_of([&] { read_curve_secret_key_file(path); });
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find(cases[index].expected), std::string::npos)
        << "case " << index << ": " << message;
  }
  const std::string missing = error_of([&] { read_curve_secret_key_file(directory_ / "none"); });
  EXPECT_NE(missing.find((directory_ / "none").string() + "' does not exist"), std::string::npos)
      << missing;
  const std::string folder = error_of([&] { read_curve_public_key_file(directory_); });
  EXPECT_NE(folder.find("is not a regular file"), std::string::npos) << folder;
  const std::string no_public =
      error_of([&] { read_curve_public_key_file(write("empty.public", "# nothing\n")); });
  EXPECT_NE(no_public.find("has no public-key"), std::string::npos) << no_public;
}

TEST_F(CurveKeys, AllowListTakesBareKeysPublicFileLinesAndComments) {
  const std::string first = generate_curve_key_pair().public_key;
  const std::string second = generate_curve_key_pair().public_key;
  // '#' is a Z85 character (never the first of a key): a comment after a key needs a blank.
  std::string hashed = generate_curve_key_pair().public_key;
  while (hashed.find('#') == std::string::npos) hashed = generate_curve_key_pair().public_key;
  const auto path = write(
      "allowed", "# coordinators\n\n  " + first + "   # laptop\n" + "public-key = \"" + second +
                     "\"\n" + hashed + " #comment\n" + first + "\n#" + std::string(39, '-') + "\n");
  EXPECT_EQ(read_curve_allow_list(path), (std::vector<std::string>{first, second, hashed}));
}

TEST_F(CurveKeys, MalformedAllowListsAreRefusedNamingTheLine) {
  const std::string key = generate_curve_key_pair().public_key;
  const std::vector<std::pair<std::string, std::string>> cases{
      // The first 38 characters: a key's first character is never '#' (a comment), while a
      // later one may be (it is a Z85 character), which made key.substr(2) a comment line in
      // about one run of 85.
      {"# a comment\n" + key.substr(0, 38) + "\n",
       "line 2: the key '" + key.substr(0, 38) + "' has 38"},
      {key + " trailing\n", "line 1: unexpected text 'trailing' after the key"},
      {"public-key = " + key + "\n", "line 1: expected public-key = \"KEY\" (the key in quotes)"},
      {"# only comments\n\n", "holds no key"},
  };
  for (const auto& [text, expected] : cases) {
    const auto path = write("allow-list", text);
    const std::string message = error_of([&] { read_curve_allow_list(path); });
    EXPECT_NE(message.find("allow-list '" + path.string() + "'"), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  }
  const std::string missing = error_of([&] { read_curve_allow_list(directory_ / "absent"); });
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;
}

TEST(Z85KeyProblem, NamesLengthAndCharacter) {
  EXPECT_EQ(z85_key_problem(generate_curve_key_pair().secret_key), "");
  EXPECT_NE(z85_key_problem("abc").find("has 3 characters, expected 40"), std::string::npos);
  EXPECT_NE(z85_key_problem(std::string(39, 'a') + "\"").find("contains '\"'"), std::string::npos);
  // "%%%%%" is 85^5 - 1 > 2^32 - 1: valid characters, invalid Z85.
  EXPECT_NE(z85_key_problem(std::string(40, '%')).find("not valid Z85"), std::string::npos);
}

}  // namespace
}  // namespace robin
