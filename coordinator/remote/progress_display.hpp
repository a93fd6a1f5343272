#pragma once
// What robin-run, robin-coordinator and robin-monolithic show while the bodies are meshed and
// set up. Two outputs:
//   plain: one log line per event ("body 'upper': meshing meshes/upper.geo (h = 0.05)",
//     "body 'upper': meshed, 1234 nodes, 2345 elements in 0.8 s", the servers' stage lines):
//     for a log file, a pipe, --quiet, or TERM=dumb;
//   live: on a terminal, one status line per body ("upper  factorization  40200 DOFs  3.1 s")
//     kept below the log and rewritten in place (ANSI cursor movement and erasure); every log
//     line is written above them (the display is the logger's sink). finish() ends it: the
//     status lines stay as last drawn, and later events are plain lines again.

#include <spdlog/logger.h>
#include <spdlog/sinks/base_sink.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "coupling/case_file.hpp"

namespace robin {

enum class ProgressOutput { plain, live };

/// live when standard error is a terminal, the run is not --quiet and TERM is set and is not
/// "dumb"; plain otherwise. `terminal_type` is TERM's value (null when unset).
ProgressOutput choose_progress_output(bool stderr_is_terminal, bool quiet,
                                      const char* terminal_type);

/// choose_progress_output for this process's standard error and environment.
ProgressOutput progress_output_of_this_process(bool quiet);

/// One body's state in the live display.
struct BodyStatus {
  std::string stage;     // "meshing", "factorization", "meshed, 1234 nodes, 2345 elements", ...
  long dof_count = 0;    // 0: not known yet (not shown)
  double seconds = 0.0;  // since the body's current request or meshing began
};

/// "upper  factorization  40200 DOFs  3.1 s", the body's name padded to `name_width`.
std::string status_line(const std::string& body, const BodyStatus& status, std::size_t name_width);

/// "body 'upper': meshing meshes/upper.geo (h = 0.05)"; "reading" for a .msh; no "(h = ...)"
/// when `size` is 0 (the script's own size). The path is shown relative to the working
/// directory when it lies below it.
std::string meshing_started_line(const std::string& body, const std::filesystem::path& mesh,
                                 double size);

/// "body 'upper': meshed, 1234 nodes, 2345 elements in 0.8 s" ("read, ..." for a .msh).
std::string meshing_finished_line(const std::string& body, const std::filesystem::path& mesh,
                                  std::size_t node_count, std::size_t element_count,
                                  double seconds);

/// The terminal codes that take the cursor back over `drawn` status lines (written below the
/// log, each ending with a newline) and erase them and everything below.
std::string erase_status_lines(std::size_t drawn);

/// The status lines, each erased first and ended by a newline.
std::string draw_status_lines(const std::vector<std::string>& lines);

/// The live display: a spdlog sink that keeps the status lines below every log line it writes.
class LiveStatusSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  /// `columns`: the terminal's width (0: unknown); longer status lines are cut to fit, so that
  /// each takes one row and the cursor movements stay right.
  LiveStatusSink(std::size_t body_count, std::FILE* terminal, std::size_t columns = 0);
  /// Replaces line `index` (adding lines up to it) and redraws (nothing once finished).
  void set_line(std::size_t index, const std::string& text);
  /// Leaves the status lines as last drawn; later log lines follow below them.
  void finish();
  bool finished();

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override;
  void flush_() override;

 private:
  void redraw();  // with mutex_ held
  std::vector<std::string> lines_;
  std::size_t drawn_ = 0;
  bool finished_ = false;
  std::FILE* terminal_;
  std::size_t columns_;
};

/// The progress of the bodies of a run, shown as `output` says (see the file comment).
class ProgressDisplay {
 public:
  /// Live: room for `body_count` status lines (the bodies are named by set_bodies).
  explicit ProgressDisplay(ProgressOutput output, std::size_t body_count = 2);
  /// The bodies, in the order of their status lines (once the case is read).
  void set_bodies(std::vector<std::string> bodies);
  ProgressOutput output() const { return output_; }
  /// The sink the run's logger must write through when live (null when plain).
  std::shared_ptr<LiveStatusSink> sink() const { return sink_; }
  /// A body's stage began or went on: plain (or after finish), `plain_line` is logged at info
  /// level on `log` (nothing when it is empty); live, the body's status line is rewritten.
  void update(const std::string& body, const BodyStatus& status, const std::string& plain_line,
              spdlog::logger& log);
  /// Ends the live display (see LiveStatusSink::finish); idempotent.
  void finish();

 private:
  std::vector<std::string> bodies_;
  ProgressOutput output_;
  std::shared_ptr<LiveStatusSink> sink_;
  std::size_t name_width_ = 0;
};

/// Reports the meshing of `definition`'s bodies (set as its `meshing` observer): their
/// meshing_started_line, "body 'upper': still meshing after 10 s" every 10 s, and
/// meshing_finished_line; live, their status lines with the seconds so far.
MeshReadObserver meshing_reporter(const CaseDefinition& definition,
                                  const std::shared_ptr<ProgressDisplay>& display,
                                  const std::shared_ptr<spdlog::logger>& log);

/// A logger named `name` on standard error at `level` ("[time] [name] [level] text"), through
/// the display's sink when it is live. Throws std::invalid_argument for an unknown level.
std::shared_ptr<spdlog::logger> make_progress_logger(const std::string& name,
                                                     const std::string& level,
                                                     const ProgressDisplay* display);

}  // namespace robin
