#include "remote/progress_display.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace robin {

namespace {

const char* const log_pattern = "[%Y-%m-%d %H:%M:%S.%e] [%n] [%^%l%$] %v";

bool is_geo(const std::filesystem::path& mesh) {
  std::string extension = mesh.extension().string();
  std::transform(
      extension.begin(), extension.end(), extension.begin(),
      [](unsigned char character) { return static_cast<char>(std::tolower(character)); });
  return extension == ".geo";
}

/// `mesh` relative to the working directory when it lies below it, as given otherwise.
std::string shown_path(const std::filesystem::path& mesh) {
  std::error_code error;
  const std::filesystem::path current = std::filesystem::current_path(error);
  if (error || !mesh.is_absolute()) return mesh.string();
  const std::filesystem::path relative = mesh.lexically_relative(current);
  if (relative.empty() || *relative.begin() == "..") return mesh.string();
  return relative.string();
}

}  // namespace

ProgressOutput choose_progress_output(bool stderr_is_terminal, bool quiet,
                                      const char* terminal_type) {
  const bool capable = terminal_type != nullptr && std::strlen(terminal_type) > 0 &&
                       std::strcmp(terminal_type, "dumb") != 0;
  return stderr_is_terminal && !quiet && capable ? ProgressOutput::live : ProgressOutput::plain;
}

ProgressOutput progress_output_of_this_process(bool quiet) {
  return choose_progress_output(::isatty(STDERR_FILENO) == 1, quiet, std::getenv("TERM"));
}

std::string status_line(const std::string& body, const BodyStatus& status, std::size_t name_width) {
  std::ostringstream line;
  line << body << std::string(name_width > body.size() ? name_width - body.size() : 0, ' ') << "  "
       << status.stage;
  if (status.dof_count > 0) line << "  " << status.dof_count << " DOFs";
  line.setf(std::ios::fixed);
  line.precision(1);
  line << "  " << status.seconds << " s";
  return line.str();
}

std::string meshing_started_line(const std::string& body, const std::filesystem::path& mesh,
                                 double size) {
  std::ostringstream line;
  line << "body '" << body << "': " << (is_geo(mesh) ? "meshing " : "reading ") << shown_path(mesh);
  if (is_geo(mesh) && size > 0.0) line << " (h = " << size << ")";
  return line.str();
}

std::string meshing_finished_line(const std::string& body, const std::filesystem::path& mesh,
                                  std::size_t node_count, std::size_t element_count,
                                  double seconds) {
  std::ostringstream line;
  line.setf(std::ios::fixed);
  line.precision(1);
  line << "body '" << body << "': " << (is_geo(mesh) ? "meshed, " : "read, ") << node_count
       << " nodes, " << element_count << " elements in " << seconds << " s";
  return line.str();
}

std::string erase_status_lines(std::size_t drawn) {
  if (drawn == 0) return "";
  // cursor to the start of the line `drawn` lines up, then erase to the end of the screen
  return "\033[" + std::to_string(drawn) + "F\033[J";
}

std::string draw_status_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += "\r\033[2K" + line + "\n";
  return text;
}

LiveStatusSink::LiveStatusSink(std::size_t body_count, std::FILE* terminal, std::size_t columns)
    : lines_(body_count), terminal_(terminal), columns_(columns) {}

void LiveStatusSink::set_line(std::size_t index, const std::string& text) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  if (index >= lines_.size()) lines_.resize(index + 1);  // a body beyond the first count
  lines_[index] = columns_ > 1 && text.size() >= columns_ ? text.substr(0, columns_ - 1) : text;
  redraw();
}

void LiveStatusSink::finish() {
  const std::lock_guard<std::mutex> lock(mutex_);
  finished_ = true;
  drawn_ = 0;  // what is drawn stays
}

bool LiveStatusSink::finished() {
  const std::lock_guard<std::mutex> lock(mutex_);
  return finished_;
}

void LiveStatusSink::redraw() {
  std::vector<std::string> shown;
  for (const std::string& line : lines_) {
    if (!line.empty()) shown.push_back(line);
  }
  const std::string text = erase_status_lines(drawn_) + draw_status_lines(shown);
  std::fwrite(text.data(), 1, text.size(), terminal_);
  std::fflush(terminal_);
  drawn_ = shown.size();
}

void LiveStatusSink::sink_it_(const spdlog::details::log_msg& message) {
  spdlog::memory_buf_t formatted;
  formatter_->format(message, formatted);
  const std::string erase = erase_status_lines(drawn_);
  std::fwrite(erase.data(), 1, erase.size(), terminal_);
  std::fwrite(formatted.data(), 1, formatted.size(), terminal_);
  drawn_ = 0;
  if (finished_) {
    std::fflush(terminal_);
  } else {
    redraw();
  }
}

void LiveStatusSink::flush_() {
  std::fflush(terminal_);
}

ProgressDisplay::ProgressDisplay(ProgressOutput output, std::size_t body_count) : output_(output) {
  if (output_ != ProgressOutput::live) return;
  winsize size{};
  const std::size_t columns =
      ::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 ? static_cast<std::size_t>(size.ws_col) : 0;
  sink_ = std::make_shared<LiveStatusSink>(body_count, stderr, columns);
}

void ProgressDisplay::set_bodies(std::vector<std::string> bodies) {
  bodies_ = std::move(bodies);
  name_width_ = 0;
  for (const std::string& body : bodies_) name_width_ = std::max(name_width_, body.size());
}

void ProgressDisplay::update(const std::string& body, const BodyStatus& status,
                             const std::string& plain_line, spdlog::logger& log) {
  const auto found = std::find(bodies_.begin(), bodies_.end(), body);
  if (sink_ && !sink_->finished() && found != bodies_.end()) {
    sink_->set_line(static_cast<std::size_t>(found - bodies_.begin()),
                    status_line(body, status, name_width_));
  } else if (!plain_line.empty()) {
    log.info("{}", plain_line);
  }
}

void ProgressDisplay::finish() {
  if (sink_) sink_->finish();
}

namespace {

/// What meshing_reporter keeps about one body's mesh.
struct BodyMesh {
  std::string name;
  std::filesystem::path path;
  double size = 0.0;
  std::chrono::steady_clock::time_point started;
  bool meshing = false;
  double reported_at = 0.0;  // seconds of the last plain "still meshing" line
};

/// Every 10 s of a body's meshing: "body 'upper': still meshing after 20 s" (plain); live, the
/// seconds of its status line.
void report_still_meshing(std::vector<BodyMesh>& bodies, ProgressDisplay& display,
                          spdlog::logger& log) {
  const auto now = std::chrono::steady_clock::now();
  for (BodyMesh& body : bodies) {
    if (!body.meshing) continue;
    const double seconds = std::chrono::duration<double>(now - body.started).count();
    std::string line;
    if (seconds - body.reported_at >= 10.0) {
      body.reported_at = seconds;
      std::ostringstream text;
      text << "body '" << body.name << "': still meshing after " << static_cast<long>(seconds)
           << " s";
      line = text.str();
    }
    display.update(body.name, {"meshing", 0, seconds}, line, log);
  }
}

}  // namespace

MeshReadObserver meshing_reporter(const CaseDefinition& definition,
                                  const std::shared_ptr<ProgressDisplay>& display,
                                  const std::shared_ptr<spdlog::logger>& log) {
  auto bodies = std::make_shared<std::vector<BodyMesh>>();
  for (const BodyCase& body : definition.bodies) {
    bodies->push_back({body.definition.name, body.mesh_path, body.mesh_options.size, {}});
  }
  MeshReadObserver observer;
  observer.started = [bodies, display, log](std::size_t index) {
    if (index >= bodies->size()) return;
    BodyMesh& body = (*bodies)[index];
    body.started = std::chrono::steady_clock::now();
    body.meshing = is_geo(body.path);
    display->update(body.name, {body.meshing ? "meshing" : "reading the mesh", 0, 0.0},
                    meshing_started_line(body.name, body.path, body.size), *log);
  };
  observer.finished = [bodies, display, log](std::size_t index, const Mesh& mesh, double seconds) {
    if (index >= bodies->size()) return;
    BodyMesh& body = (*bodies)[index];
    body.meshing = false;
    std::ostringstream stage;
    stage << (is_geo(body.path) ? "meshed, " : "read, ") << mesh.node_count() << " nodes, "
          << mesh.element_count() << " elements";
    display->update(body.name, {stage.str(), 0, seconds},
                    meshing_finished_line(body.name, body.path, mesh.node_count(),
                                          mesh.element_count(), seconds),
                    *log);
  };
  observer.waiting = [bodies, display, log] { report_still_meshing(*bodies, *display, *log); };
  return observer;
}

std::shared_ptr<spdlog::logger> make_progress_logger(const std::string& name,
                                                     const std::string& level,
                                                     const ProgressDisplay* display) {
  const auto parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off") {
    throw std::invalid_argument("unknown log level '" + level + "'");
  }
  spdlog::drop(name);
  std::shared_ptr<spdlog::logger> log;
  if (display != nullptr && display->sink()) {
    log = std::make_shared<spdlog::logger>(name, display->sink());
    spdlog::register_logger(log);
  } else {
    log = spdlog::stderr_color_mt(name);
  }
  log->set_pattern(log_pattern);
  log->set_level(parsed);
  return log;
}

}  // namespace robin
