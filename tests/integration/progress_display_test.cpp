// The setup progress display (coordinator/remote/progress_display.hpp). Unit tests of its
// rendering (here rather than in unit/ because it lives in robin_console, which the integration
// tests link): the terminal/plain choice from an injected "is a terminal" flag, --quiet and
// TERM; the status and meshing lines; the terminal codes that rewrite the status lines in
// place; the live sink's byte stream around log lines and after finish(). Then through the
// real binaries, whose standard error is a file (not a terminal): robin-run, robin-coordinator
// and robin-monolithic print the plain meshing lines naming each body, its .geo, h, and its
// node and element counts, and no terminal codes.

#include "remote/progress_display.hpp"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <cstdio>
#include <regex>

#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::read_text;
using testing::run_to_end;
using testing::TemporaryDirectory;

TEST(ProgressDisplay, LiveOnlyOnACapableTerminalWithoutQuiet) {
  EXPECT_EQ(choose_progress_output(true, false, "xterm-256color"), ProgressOutput::live);
  EXPECT_EQ(choose_progress_output(false, false, "xterm-256color"), ProgressOutput::plain);
  EXPECT_EQ(choose_progress_output(true, true, "xterm-256color"), ProgressOutput::plain);
  EXPECT_EQ(choose_progress_output(true, false, "dumb"), ProgressOutput::plain);
  EXPECT_EQ(choose_progress_output(true, false, ""), ProgressOutput::plain);
  EXPECT_EQ(choose_progress_output(true, false, nullptr), ProgressOutput::plain);
}

TEST(ProgressDisplay, FormatsStatusAndMeshingLines) {
  EXPECT_EQ(status_line("upper", {"factorization", 40200, 3.14}, 5),
            "upper  factorization  40200 DOFs  3.1 s");
  EXPECT_EQ(status_line("flat", {"meshing", 0, 0.0}, 8), "flat      meshing  0.0 s");
  EXPECT_EQ(meshing_started_line("upper", "/elsewhere/upper.geo", 0.05),
            "body 'upper': meshing /elsewhere/upper.geo (h = 0.05)");
  EXPECT_EQ(meshing_started_line("upper", "/elsewhere/upper.geo", 0.0),
            "body 'upper': meshing /elsewhere/upper.geo");
  EXPECT_EQ(meshing_started_line("flat", "/elsewhere/flat.msh", 0.05),
            "body 'flat': reading /elsewhere/flat.msh");
  // below the working directory: shown relative to it
  EXPECT_EQ(
      meshing_started_line("upper", std::filesystem::current_path() / "meshes" / "u.geo", 0.1),
      "body 'upper': meshing meshes/u.geo (h = 0.1)");
  EXPECT_EQ(meshing_finished_line("upper", "u.geo", 1234, 2345, 0.84),
            "body 'upper': meshed, 1234 nodes, 2345 elements in 0.8 s");
  EXPECT_EQ(meshing_finished_line("flat", "f.msh", 10, 20, 0.0),
            "body 'flat': read, 10 nodes, 20 elements in 0.0 s");
}

TEST(ProgressDisplay, TerminalCodesRewriteTheStatusLinesInPlace) {
  EXPECT_EQ(erase_status_lines(0), "");
  EXPECT_EQ(erase_status_lines(2), "\033[2F\033[J");  // up 2 lines to column 1, erase below
  EXPECT_EQ(draw_status_lines({"a", "b"}), "\r\033[2Ka\n\r\033[2Kb\n");
}

std::string file_contents(std::FILE* file) {
  std::fflush(file);
  std::rewind(file);
  std::string text;
  for (int character; (character = std::fgetc(file)) != EOF;) {
    text += static_cast<char>(character);
  }
  return text;
}

TEST(ProgressDisplay, LiveSinkKeepsTheStatusLinesBelowTheLog) {
  std::FILE* terminal = std::tmpfile();
  ASSERT_NE(terminal, nullptr);
  auto sink = std::make_shared<LiveStatusSink>(2, terminal);
  spdlog::logger log("live-test", sink);
  log.set_pattern("%v");
  sink->set_line(0, "upper  meshing  0.0 s");
  log.info("a log line");
  sink->set_line(1, "lower  assembly  10 DOFs  0.1 s");
  sink->finish();
  sink->set_line(0, "ignored once finished");
  log.info("after");
  const std::string expected =
      draw_status_lines({"upper  meshing  0.0 s"}) + erase_status_lines(1) + "a log line\n" +
      draw_status_lines({"upper  meshing  0.0 s"}) + erase_status_lines(1) +
      draw_status_lines({"upper  meshing  0.0 s", "lower  assembly  10 DOFs  0.1 s"}) + "after\n";
  EXPECT_EQ(file_contents(terminal), expected);
  std::fclose(terminal);
  // a status line as wide as the terminal is cut to one row
  std::FILE* narrow = std::tmpfile();
  ASSERT_NE(narrow, nullptr);
  LiveStatusSink cut(1, narrow, 10);
  cut.set_line(0, "cylinder  factorization  69438 DOFs  3.0 s");
  EXPECT_EQ(file_contents(narrow), draw_status_lines({"cylinder "}));
  std::fclose(narrow);
}

TEST(ProgressDisplay, PlainLinesWhenPlainOrFinished) {
  std::ostringstream stream;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(stream);
  spdlog::logger log("plain-test", sink);
  log.set_pattern("%v");
  ProgressDisplay plain(ProgressOutput::plain);
  plain.set_bodies({"upper", "lower"});
  plain.update("upper", {"meshing", 0, 0.0}, "body 'upper': meshing u.geo", log);
  plain.update("lower", {"factorization", 10, 1.0}, "", log);  // nothing new to say
  EXPECT_EQ(stream.str(), "body 'upper': meshing u.geo\n");
  EXPECT_EQ(plain.sink(), nullptr);
  // a live display that has finished (the iteration began) falls back to plain lines
  ProgressDisplay live(ProgressOutput::live);
  live.set_bodies({"upper", "lower"});
  ASSERT_NE(live.sink(), nullptr);
  live.finish();
  live.update("lower", {"fields: output", 10, 1.0}, "body 'lower' fields: output", log);
  EXPECT_EQ(stream.str(), "body 'upper': meshing u.geo\nbody 'lower' fields: output\n");
}

// ---- Through the real binaries ------------------------------------------------------------

/// Checks that `log` (a tool's standard error in a file) has the plain meshing lines of
/// examples/two_blocks.toml's bodies and no terminal codes.
void expect_plain_meshing_lines(const std::string& log, const std::string& tool) {
  for (const std::string body : {"lower", "upper"}) {
    const std::string started =
        "body '" + body + "': meshing examples/meshes/block_" + body + ".geo (h = 0.1)";
    const std::regex finished("body '" + body +
                              "': meshed, [1-9][0-9]* nodes, [1-9][0-9]* elements in "
                              "[0-9]+\\.[0-9] s");
    EXPECT_NE(log.find(started), std::string::npos) << tool << "\n" << log;
    EXPECT_TRUE(std::regex_search(log, finished)) << tool << " " << body << "\n" << log;
    EXPECT_LT(log.find(started), log.find("body '" + body + "': meshed")) << tool;
  }
  EXPECT_EQ(log.find('\033'), std::string::npos) << tool << ": terminal codes in a file";
}

TEST(ProgressDisplayTools, PlainMeshingLinesInALogFile) {
  const TemporaryDirectory directory("robin-progress-lines");
  // run from the repository, so that the meshes are shown as examples/meshes/...
  const std::filesystem::path previous = std::filesystem::current_path();
  std::filesystem::current_path(example("..").lexically_normal());
  const std::string case_file = "examples/two_blocks.toml";
  for (const std::string tool : {"robin-run", "robin-monolithic"}) {
    const std::filesystem::path log = directory.path() / (tool + ".stderr");
    EXPECT_EQ(run_to_end(tool, {case_file, "--output", (directory.path() / tool).string()}, log),
              "exited with status 0")
        << read_text(log);
    expect_plain_meshing_lines(read_text(log), tool);
  }
  std::array<std::unique_ptr<SubdomainServer>, 2> servers;
  std::vector<std::string> arguments = {case_file, "--output",
                                        (directory.path() / "robin-coordinator").string()};
  for (int index = 0; index < 2; ++index) {
    servers[index] = std::make_unique<SubdomainServer>(
        index == 0 ? "lower" : "upper", testing::server_options(directory.path() / "logs"));
    servers[index]->await_listening();
    arguments.insert(arguments.end(), {"--subdomain", servers[index]->endpoint()});
  }
  const std::filesystem::path log = directory.path() / "robin-coordinator.stderr";
  EXPECT_EQ(run_to_end("robin-coordinator", arguments, log), "exited with status 0")
      << read_text(log);
  expect_plain_meshing_lines(read_text(log), "robin-coordinator");
  std::filesystem::current_path(previous);
}

}  // namespace
}  // namespace robin
