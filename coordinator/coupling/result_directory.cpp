#include "coupling/result_directory.hpp"

#include <sodium.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "protocol_version.hpp"
#include "robin_version.hpp"

namespace robin {
namespace {

namespace fs = std::filesystem;

/// The names every run may write (besides the .vtu files and those listed in summary.json).
const std::set<std::string> run_file_names = {
    "summary.json", "history.csv", "contact.csv",     "solution.pvd",
    "contact.png",  "history.png", "checkpoint.json", "checkpoint-iterates.bin"};
/// Kept by a resume (checkpoint.hpp), removed by commit().
const std::set<std::string> checkpoint_names = {"checkpoint.json", "checkpoint-iterates.bin"};
const std::string staging_prefix = ".staging-";
const std::string log_directory_name = "logs";  // robin-run's server logs: written before us

std::string hex(const unsigned char* bytes, std::size_t count) {
  static const char digits[] = "0123456789abcdef";
  std::string text;
  for (std::size_t k = 0; k < count; ++k) {
    text += digits[bytes[k] >> 4];
    text += digits[bytes[k] & 0xF];
  }
  return text;
}

std::string random_run_id() {
  std::random_device device;
  std::array<unsigned char, 16> bytes{};
  for (unsigned char& byte : bytes) byte = static_cast<unsigned char>(device() & 0xFF);
  return hex(bytes.data(), bytes.size());
}

std::vector<std::string> entry_names(const fs::path& directory) {
  std::vector<std::string> names;
  std::error_code error;
  for (fs::directory_iterator entry(directory, error), end; !error && entry != end;
       entry.increment(error)) {
    names.push_back(entry->path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// A name from an earlier summary.json "files" list that may be removed: one plain entry of
/// the directory, never a path leading elsewhere.
bool is_plain_entry_name(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
         name.find('\0') == std::string::npos;
}

/// The entries the previous run listed in its summary.json (empty when there is none or it
/// cannot be read: then only the fixed names are removed).
std::set<std::string> previous_run_files(const fs::path& directory) {
  std::set<std::string> names;
  std::ifstream file(directory / "summary.json");
  if (!file) return names;
  const nlohmann::json summary = nlohmann::json::parse(file, nullptr, false);
  if (!summary.is_object() || !summary.contains("files") || !summary["files"].is_array())
    return names;
  for (const nlohmann::json& name : summary["files"]) {
    if (name.is_string() && is_plain_entry_name(name.get<std::string>()))
      names.insert(name.get<std::string>());
  }
  return names;
}

bool belongs_to_a_run(const std::string& name, const std::set<std::string>& listed) {
  const bool vtu = name.size() > 4 && name.compare(name.size() - 4, 4, ".vtu") == 0;
  // a temporary file of write_file_atomically left by a killed run ('.summary.json.tmp-...')
  const bool temporary = name.rfind('.', 0) == 0 && name.find(".tmp-") != std::string::npos;
  return listed.count(name) > 0 || run_file_names.count(name) > 0 || vtu || temporary ||
         name.rfind(staging_prefix, 0) == 0;
}

/// The file's SHA-256, or "" when it cannot be read (recorded as null).
std::string sha256_if_readable(const fs::path& path) {
  try {
    return file_sha256(path);
  } catch (const std::runtime_error&) {
    return "";
  }
}

std::string describe_entries(const std::vector<std::string>& names) {
  std::ostringstream text;
  for (std::size_t k = 0; k < names.size() && k < 5; ++k) text << (k ? ", " : "") << names[k];
  if (names.size() > 5) text << ", ... (" << names.size() << " entries)";
  return text.str();
}

}  // namespace

void check_result_directory(const fs::path& directory, ExistingResults policy,
                            const std::set<std::string>& ignored) {
  std::error_code error;
  if (!fs::exists(directory, error)) return;
  if (!fs::is_directory(directory, error)) {
    throw ResultDirectoryError("the output '" + directory.string() +
                               "' exists and is not a directory");
  }
  if (policy != ExistingResults::refuse) return;
  std::vector<std::string> names = entry_names(directory);
  names.erase(std::remove_if(names.begin(), names.end(),
                             [&](const std::string& name) { return ignored.count(name) > 0; }),
              names.end());
  if (names.empty()) return;
  throw ResultDirectoryError("the output directory '" + directory.string() + "' is not empty (" +
                             describe_entries(names) +
                             "): choose a new or empty directory, or pass --overwrite to replace "
                             "the results of an earlier run there");
}

std::string file_sha256(const fs::path& path) {
  if (sodium_init() < 0) throw std::runtime_error("libsodium cannot be initialized");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("cannot read '" + path.string() + "' to hash it");
  crypto_hash_sha256_state state;
  crypto_hash_sha256_init(&state);
  std::array<char, 65536> buffer{};
  while (file) {
    file.read(buffer.data(), buffer.size());
    const std::streamsize count = file.gcount();
    if (count > 0) {
      crypto_hash_sha256_update(&state, reinterpret_cast<const unsigned char*>(buffer.data()),
                                static_cast<unsigned long long>(count));
    }
  }
  if (file.bad()) throw std::runtime_error("cannot read '" + path.string() + "' to hash it");
  std::array<unsigned char, crypto_hash_sha256_BYTES> digest{};
  crypto_hash_sha256_final(&state, digest.data());
  return hex(digest.data(), digest.size());
}

std::string utc_timestamp() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm parts{};
  gmtime_r(&now, &parts);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y-%m-%dT%H:%M:%SZ", &parts);
  return text.data();
}

bool write_durably(const fs::path& path, const std::string& bytes, const char* mode) {
  std::FILE* file = std::fopen(path.c_str(), mode);
  if (file == nullptr) return false;
  bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  written = std::fflush(file) == 0 && written;
  written = ::fsync(::fileno(file)) == 0 && written;
  return std::fclose(file) == 0 && written;
}

void write_file_atomically(const fs::path& path, const std::string& text) {
  static std::atomic<unsigned> counter{0};
  std::ostringstream name;
  name << '.' << path.filename().string() << ".tmp-" << ::getpid() << '-' << counter++;
  const fs::path temporary = path.parent_path() / name.str();
  const bool written = write_durably(temporary, text, "wb");
  std::error_code error;
  if (written) fs::rename(temporary, path, error);
  if (!written || error) {
    fs::remove(temporary, error);
    throw std::runtime_error("cannot write '" + path.string() + "'");
  }
}

ResultDirectory::ResultDirectory(fs::path directory, ExistingResults policy, std::string tool,
                                 const fs::path& case_file)
    : directory_(std::move(directory)),
      tool_(std::move(tool)),
      case_file_(case_file.string()),
      case_sha256_(sha256_if_readable(case_file)),
      run_id_(random_run_id()),
      started_(utc_timestamp()) {
  // robin-run's server logs are written before the run starts: they are this run's
  check_result_directory(directory_, policy, {log_directory_name});
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error) {
    throw ResultDirectoryError("cannot create the output directory '" + directory_.string() +
                               "': " + error.message());
  }
  const std::set<std::string> listed = previous_run_files(directory_);
  for (const std::string& name : entry_names(directory_)) {
    if (name == log_directory_name) continue;
    if (policy == ExistingResults::resume && checkpoint_names.count(name) > 0) continue;
    if (belongs_to_a_run(name, listed)) {
      fs::remove_all(directory_ / name, error);
      if (error) {
        throw ResultDirectoryError("cannot remove '" + (directory_ / name).string() +
                                   "' of an earlier run: " + error.message());
      }
    } else {
      leftovers_.push_back(name);
    }
  }
  staging_ = directory_ / (staging_prefix + run_id_);
  fs::create_directory(staging_, error);
  if (error) {
    throw ResultDirectoryError("cannot write into the output directory '" + directory_.string() +
                               "': " + error.message());
  }
  write_file_atomically(directory_ / "summary.json", record("running").dump(2) + "\n");
}

ResultDirectory::~ResultDirectory() {
  if (!finished_) fail(RunFailure::failed, "the run ended before writing its results");
}

nlohmann::json ResultDirectory::record(const std::string& status) const {
  const std::string protocol =
      std::to_string(protocol::protocol_major) + "." + std::to_string(protocol::protocol_minor);
  nlohmann::json document = {
      {"status", status},
      {"versions", {{"product", product_version}, {"protocol", protocol}}},
      {"run_id", run_id_},
      {"tool", tool_},
      {"case", case_file_},
      {"case_sha256", case_sha256_.empty() ? nlohmann::json() : nlohmann::json(case_sha256_)},
      {"started", started_},
      {"ended", nullptr}};
  for (const auto& [key, value] : additions_.items()) document[key] = value;
  return document;
}

void ResultDirectory::add_to_record(const std::string& key, nlohmann::json value) {
  additions_[key] = std::move(value);
  if (finished_) return;
  write_file_atomically(
      directory_ / "summary.json",
      record("running").dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

void ResultDirectory::commit(nlohmann::json summary) {
  std::vector<std::string> files;
  for (const std::string& name : entry_names(staging_)) {
    std::error_code error;
    fs::rename(staging_ / name, directory_ / name, error);
    if (error) {
      throw std::runtime_error("cannot move the result '" + name + "' into '" +
                               directory_.string() + "': " + error.message());
    }
    files.push_back(name);
  }
  files.push_back("summary.json");
  nlohmann::json document = record(summary.value("status", std::string("unknown")));
  document["ended"] = utc_timestamp();
  document["files"] = files;
  for (auto& [key, value] : summary.items()) document[key] = value;
  // invalid UTF-8 (e.g. from a path) is replaced rather than thrown
  write_file_atomically(
      directory_ / "summary.json",
      document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  finished_ = true;
  remove_staging();
  std::error_code error;
  // the run is complete: nothing to resume
  for (const std::string& name : checkpoint_names) fs::remove(directory_ / name, error);
}

void ResultDirectory::fail(RunFailure failure, const std::string& message) noexcept {
  finished_ = true;
  remove_staging();
  try {
    nlohmann::json document = record(failure == RunFailure::interrupted ? "interrupted" : "failed");
    document["ended"] = utc_timestamp();
    document["converged"] = false;
    document["message"] = message;
    write_file_atomically(
        directory_ / "summary.json",
        document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  } catch (...) {
    // the directory is gone or read-only: nothing more can be recorded
  }
}

void record_failed_start(const fs::path& directory, ExistingResults policy, const std::string& tool,
                         const fs::path& case_file, const std::string& message) {
  ResultDirectory results(directory, policy, tool, case_file);
  results.fail(RunFailure::failed, message);
}

void ResultDirectory::remove_staging() noexcept {
  std::error_code error;
  if (!staging_.empty()) fs::remove_all(staging_, error);
}

}  // namespace robin
