#include "coupling/checkpoint.hpp"

#include <toml++/toml.h>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "coupling/checkpoint_encoding.hpp"
#include "coupling/result_directory.hpp"

namespace robin {

const char* const checkpoint_file_name = "checkpoint.json";
const char* const checkpoint_iterates_file_name = "checkpoint-iterates.bin";

namespace {

/// One record of checkpoint-iterates.bin: the count, then the values.
std::string iterate_record(const Eigen::VectorXd& iterate) {
  const std::uint64_t count = static_cast<std::uint64_t>(iterate.size());
  std::string bytes(reinterpret_cast<const char*>(&count), sizeof count);
  bytes.append(reinterpret_cast<const char*>(iterate.data()),
               static_cast<std::size_t>(iterate.size()) * sizeof(double));
  return bytes;
}

void append_to_file(const std::filesystem::path& path, const std::string& bytes) {
  if (!write_durably(path, bytes, "ab")) {
    throw std::runtime_error("cannot write '" + path.string() + "'");
  }
}

/// The first `count` records of checkpoint-iterates.bin.
std::vector<Eigen::VectorXd> read_iterates(const std::filesystem::path& path, int count) {
  std::ifstream file(path, std::ios::binary);
  if (!file && count > 0) throw CheckpointFormatError("'" + path.string() + "' is missing");
  std::vector<Eigen::VectorXd> iterates;
  constexpr std::uint64_t largest = std::uint64_t{1} << 32;
  for (int index = 0; index < count; ++index) {
    std::uint64_t size = 0;
    file.read(reinterpret_cast<char*>(&size), sizeof size);
    if (!file || size > largest) break;
    Eigen::VectorXd iterate(static_cast<Eigen::Index>(size));
    file.read(reinterpret_cast<char*>(iterate.data()),
              static_cast<std::streamsize>(size * sizeof(double)));
    if (!file) break;
    iterates.push_back(std::move(iterate));
  }
  if (static_cast<int>(iterates.size()) != count) {
    throw CheckpointFormatError("'" + path.string() + "' holds " + std::to_string(iterates.size()) +
                                " whole iterates, expected " + std::to_string(count));
  }
  return iterates;
}

/// The shortest %g form that reads back to `value` ("1e-07", "0.05").
std::string shortest(double value) {
  char text[32];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(text, sizeof text, "%.*g", precision, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

/// Every leaf of a TOML table under its key path ("a.b", "body[2].x").
void flatten(const toml::node& node, const std::string& path,
             std::map<std::string, std::string>& leaves) {
  if (const toml::table* table = node.as_table()) {
    for (const auto& [key, value] : *table) {
      flatten(value, path.empty() ? std::string(key.str()) : path + "." + std::string(key.str()),
              leaves);
    }
  } else if (const toml::array* array = node.as_array();
             array != nullptr && array->is_array_of_tables()) {
    for (std::size_t index = 0; index < array->size(); ++index) {
      flatten(*array->get(index), path + "[" + std::to_string(index + 1) + "]", leaves);
    }
  } else {
    std::ostringstream text;
    if (const auto* number = node.as_floating_point()) {
      text << shortest(number->get());
    } else {
      node.visit([&text](const auto& value) { text << value; });
    }
    leaves[path] = text.str();
  }
}

std::map<std::string, std::string> leaves_of(const std::string& text, const char* which) {
  std::map<std::string, std::string> leaves;
  try {
    flatten(toml::parse(text), "", leaves);
  } catch (const toml::parse_error& error) {
    leaves["(" + std::string(which) + " text)"] =
        std::string("does not parse: ") + std::string(error.description());
  }
  return leaves;
}

}  // namespace

std::vector<std::string> toml_differences(const std::string& before, const std::string& after,
                                          std::size_t limit) {
  const auto old_leaves = leaves_of(before, "checkpointed");
  const auto new_leaves = leaves_of(after, "current");
  std::map<std::string, std::pair<std::string, std::string>> changed;
  for (const auto& [key, value] : old_leaves) changed[key].first = value;
  for (const auto& [key, value] : new_leaves) changed[key].second = value;
  std::vector<std::string> lines;
  for (const auto& [key, values] : changed) {
    const bool in_old = old_leaves.count(key) > 0, in_new = new_leaves.count(key) > 0;
    if (in_old && in_new && values.first == values.second) continue;
    if (lines.size() == limit) {
      lines.emplace_back("...");
      break;
    }
    lines.push_back(key + ": " + (in_old ? values.first : "(absent)") + " -> " +
                    (in_new ? values.second : "(absent)"));
  }
  return lines;
}

CheckpointWriter::CheckpointWriter(std::filesystem::path directory)
    : directory_(std::move(directory)) {}

void CheckpointWriter::write(const RunCheckpoint& checkpoint) {
  // the completed steps' iterates, then the current loop's (without copying them)
  std::vector<const Eigen::VectorXd*> iterates;
  for (const LoadStepCheckpoint& step : checkpoint.steps) {
    for (const Eigen::VectorXd& iterate : step.iteration.iterates) iterates.push_back(&iterate);
  }
  for (const Eigen::VectorXd& iterate : checkpoint.iteration.iterates) iterates.push_back(&iterate);
  const std::filesystem::path iterates_path = directory_ / checkpoint_iterates_file_name;
  if (first_ || iterates.size() < iterates_written_) {
    std::string bytes;
    for (const Eigen::VectorXd* iterate : iterates) bytes += iterate_record(*iterate);
    write_file_atomically(iterates_path, bytes);
    first_ = false;
  } else {
    std::string bytes;
    for (std::size_t index = iterates_written_; index < iterates.size(); ++index) {
      bytes += iterate_record(*iterates[index]);
    }
    append_to_file(iterates_path, bytes);
  }
  iterates_written_ = iterates.size();
  nlohmann::json steps = nlohmann::json::array();
  for (const LoadStepCheckpoint& step : checkpoint.steps) steps.push_back(to_json(step));
  const nlohmann::json document = {{"format", RunCheckpoint::current_format},
                                   {"run_id", checkpoint.run_id},
                                   {"first_run_id", checkpoint.first_run_id},
                                   {"started", checkpoint.started},
                                   {"case_file", checkpoint.case_file},
                                   {"case_sha256", checkpoint.case_sha256},
                                   {"case_text", checkpoint.case_text},
                                   {"overrides", checkpoint.overrides},
                                   {"options", checkpoint.options},
                                   {"step", checkpoint.step},
                                   {"load_steps", steps},
                                   {"loop", to_json(checkpoint.iteration)}};
  write_file_atomically(
      directory_ / checkpoint_file_name,
      document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

BackgroundCheckpointWriter::BackgroundCheckpointWriter(std::filesystem::path directory)
    : writer_(std::move(directory)), thread_([this] { write_in_turn(); }) {}

BackgroundCheckpointWriter::~BackgroundCheckpointWriter() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();  // the thread writes what is waiting before it ends
}

void BackgroundCheckpointWriter::write(const RunCheckpoint& checkpoint) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    throw_error();
    waiting_ = checkpoint;
  }
  changed_.notify_all();
}

void BackgroundCheckpointWriter::finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return !waiting_ && !writing_; });
  throw_error();
}

void BackgroundCheckpointWriter::throw_error() {
  if (!error_) return;
  std::exception_ptr error = error_;
  error_ = nullptr;
  std::rethrow_exception(error);
}

void BackgroundCheckpointWriter::write_in_turn() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return waiting_ || stopping_; });
    if (!waiting_) return;  // stopping, nothing left to write
    const RunCheckpoint checkpoint = std::move(*waiting_);
    waiting_.reset();
    writing_ = true;
    lock.unlock();
    std::exception_ptr error;
    try {
      writer_.write(checkpoint);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    writing_ = false;
    if (error) error_ = error;
    changed_.notify_all();
  }
}

RunCheckpoint read_checkpoint(const std::filesystem::path& directory) {
  const std::filesystem::path path = directory / checkpoint_file_name;
  std::ifstream file(path);
  if (!file) {
    throw CheckpointFormatError("there is no checkpoint '" + path.string() +
                                "' (a run writes it after its first iteration and removes it "
                                "once its results are written)");
  }
  const nlohmann::json document = nlohmann::json::parse(file, nullptr, false);
  try {
    if (document.is_discarded()) throw CheckpointFormatError("it is not JSON");
    if (decode_integer(document, "format") != RunCheckpoint::current_format) {
      throw CheckpointFormatError("it has format " + document.at("format").dump() +
                                  ", this program reads format " +
                                  std::to_string(RunCheckpoint::current_format));
    }
    RunCheckpoint checkpoint;
    checkpoint.run_id = decode_text(document, "run_id");
    checkpoint.first_run_id = decode_text(document, "first_run_id");
    checkpoint.started = decode_text(document, "started");
    checkpoint.case_file = decode_text(document, "case_file");
    checkpoint.case_sha256 = decode_text(document, "case_sha256");
    checkpoint.case_text = decode_text(document, "case_text");
    const nlohmann::json& overrides = member(document, "overrides");
    if (!overrides.is_array()) throw CheckpointFormatError("'overrides' is not an array");
    for (const nlohmann::json& value : overrides) {
      if (!value.is_string()) throw CheckpointFormatError("'overrides' holds a non-string");
      checkpoint.overrides.push_back(value.get<std::string>());
    }
    checkpoint.options = member(document, "options");
    checkpoint.step = decode_integer(document, "step");
    const nlohmann::json& steps = member(document, "load_steps");
    if (!steps.is_array()) throw CheckpointFormatError("'load_steps' is not an array");
    for (const nlohmann::json& step : steps) {
      checkpoint.steps.push_back(load_step_checkpoint_from_json(step));
      if (checkpoint.steps.back().step != static_cast<int>(checkpoint.steps.size())) {
        throw CheckpointFormatError("'load_steps' holds step " +
                                    std::to_string(checkpoint.steps.back().step) + " at place " +
                                    std::to_string(checkpoint.steps.size()));
      }
    }
    if (checkpoint.step < 0 ||
        (checkpoint.step == 0 ? !checkpoint.steps.empty()
                              : checkpoint.step != static_cast<int>(checkpoint.steps.size()) + 1)) {
      throw CheckpointFormatError("its 'step' " + std::to_string(checkpoint.step) + " follows " +
                                  std::to_string(checkpoint.steps.size()) + " completed steps");
    }
    checkpoint.iteration = iteration_checkpoint_from_json(member(document, "loop"));
    int count = checkpoint.iteration.iteration;
    for (const LoadStepCheckpoint& step : checkpoint.steps) count += step.iteration.iteration;
    std::vector<Eigen::VectorXd> iterates =
        read_iterates(directory / checkpoint_iterates_file_name, count);
    auto next = std::make_move_iterator(iterates.begin());
    for (LoadStepCheckpoint& step : checkpoint.steps) {
      step.iteration.iterates.assign(next, next + step.iteration.iteration);
      next += step.iteration.iteration;
    }
    checkpoint.iteration.iterates.assign(next, std::make_move_iterator(iterates.end()));
    return checkpoint;
  } catch (const CheckpointFormatError& error) {
    throw CheckpointFormatError("the checkpoint '" + path.string() +
                                "' cannot be used: " + error.what());
  } catch (const nlohmann::json::exception& error) {
    throw CheckpointFormatError("the checkpoint '" + path.string() +
                                "' cannot be used: " + error.what());
  }
}

}  // namespace robin
