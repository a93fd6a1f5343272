// Quasi-static load steps through real processes:
//  - robin-run on examples/non_matching_blocks_steps.toml (two robin-subdomain servers): exit 0;
//    solution.pvd is the time series of both bodies (timesteps 0.5, 1, 2); steps.csv has one row
//    per step; history.csv starts with the columns step and load_factor; each step's
//    contact.csv has the pressure t_k p of the patch test, p from the formula of the example;
//    summary.json lists the steps;
//  - robin-monolithic on the same file writes the same layout with the same pressures, and
//    every step of robin-run equals its step to 1e-8 on the contact forces;
//  - the Python server (protocol 2.1) owns one body of a stepped run and gives the same answer;
//  - a stepped case against a server that announces protocol 2.0 (robin-subdomain
//    --protocol-minor 0) is refused before any step, naming the server and both versions.

#include <gtest/gtest.h>
#include <sys/prctl.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "coupling/coupled_run.hpp"
#include "coupling/step_outputs.hpp"
#include "protocol_version.hpp"
#include "remote/conformance_check.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::ProcessOutcome;
using testing::read_csv;
using testing::run_tool;
using testing::TemporaryDirectory;

/// The exact pressure of the patch test at load factor 1 (examples/non_matching_blocks.toml).
double exact_patch_pressure() {
  const double lower = 0.5 * (1.0 - 0.3 * 0.3) / 1000.0;
  const double upper = 0.4 * (1.0 - 0.25 * 0.25) / 400.0;
  return 0.01 / (lower + upper);
}

std::vector<double> numbers(const std::vector<std::string>& cells) {
  std::vector<double> values;
  for (const std::string& cell : cells) values.push_back(std::stod(cell));
  return values;
}

double largest_relative_difference(const std::vector<double>& values, double expected) {
  double error = 0.0;
  for (const double value : values) error = std::max(error, std::abs(value - expected) / expected);
  return values.empty() ? 1.0 : error;
}

TEST(LoadStepsService, RobinRunAndRobinMonolithicWriteEveryStepOfThePatchTest) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory output("load-steps");
  const std::filesystem::path coupled = output.path() / "robin";
  const std::filesystem::path monolithic = output.path() / "monolithic";
  const std::string case_file = example("non_matching_blocks_steps.toml").string();
  const ProcessOutcome run =
      run_tool("robin-run", {case_file, "--output", coupled.string()}, output.path(), 240.0);
  ASSERT_EQ(run.exit, "exited with status 0") << run.errors;
  const ProcessOutcome reference = run_tool(
      "robin-monolithic", {case_file, "--output", monolithic.string()}, output.path(), 240.0);
  ASSERT_EQ(reference.exit, "exited with status 0") << reference.errors;

  const std::vector<double> factors{0.5, 1.0, 2.0};
  for (const std::filesystem::path& directory : {coupled, monolithic}) {
    // solution.pvd: one DataSet per step and body, timestep = the load factor.
    const std::string pvd = testing::file_text(directory / "solution.pvd");
    const std::regex dataset(
        "<DataSet timestep=\"([^\"]+)\" group=\"\" part=\"([01])\" "
        "file=\"(steps/step_00[123]/(lower|upper)\\.vtu)\"/>");
    std::vector<double> timesteps;
    for (auto match = std::sregex_iterator(pvd.begin(), pvd.end(), dataset);
         match != std::sregex_iterator(); ++match) {
      timesteps.push_back(std::stod((*match)[1]));
      EXPECT_TRUE(std::filesystem::is_regular_file(directory / (*match)[3].str())) << (*match)[3];
    }
    EXPECT_EQ(timesteps, (std::vector<double>{0.5, 0.5, 1.0, 1.0, 2.0, 2.0})) << pvd;
    const auto steps = read_csv(directory / "steps.csv");
    EXPECT_EQ(numbers(steps.at("load_factor")), factors) << directory;
    for (const std::string& status : steps.at("status")) EXPECT_EQ(status, "converged");
    for (std::size_t k = 0; k < factors.size(); ++k) {
      const auto contact =
          read_csv(directory / step_directory(static_cast<int>(k + 1), 3) / "contact.csv");
      const double error = largest_relative_difference(numbers(contact.at("pressure")),
                                                       factors[k] * exact_patch_pressure());
      EXPECT_LE(error, 1e-8) << directory << " step " << k + 1;
    }
    std::ifstream summary_file(directory / "summary.json");
    const nlohmann::json summary = nlohmann::json::parse(summary_file);
    ASSERT_EQ(summary.at("load_steps").size(), 3u);
    EXPECT_EQ(summary.at("load_steps").at(2).at("load_factor").get<double>(), 2.0);
    // The top-level files are the last step's.
    EXPECT_EQ(testing::file_text(directory / "contact.csv"),
              testing::file_text(directory / "steps/step_003/contact.csv"));
  }
  // history.csv: every iteration of every step, the step first.
  const auto history = read_csv(coupled / "history.csv");
  ASSERT_TRUE(history.count("step") == 1 && history.count("load_factor") == 1);
  EXPECT_EQ(history.at("step").front(), "1");
  EXPECT_EQ(history.at("step").back(), "3");
  EXPECT_EQ(testing::file_text(coupled / "history.csv").rfind("step,load_factor,iteration,", 0),
            0u);
  // Robin equals the monolithic reference at every step.
  for (int step = 1; step <= 3; ++step) {
    const auto robin = read_csv(coupled / step_directory(step, 3) / "contact.csv");
    const auto mono = read_csv(monolithic / step_directory(step, 3) / "contact.csv");
    const std::vector<double> lambda = numbers(robin.at("lambda1"));
    const std::vector<double> expected = numbers(mono.at("lambda1"));
    ASSERT_EQ(lambda.size(), expected.size());
    double scale = 0.0, difference = 0.0;
    for (std::size_t i = 0; i < lambda.size(); ++i) {
      scale = std::max(scale, std::abs(expected[i]));
      difference = std::max(difference, std::abs(lambda[i] - expected[i]));
    }
    EXPECT_LE(difference, 1e-8 * scale) << "step " << step;
  }
}

TEST(LoadStepsService, PythonServerServesTheStepsOfABody) {
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const TemporaryDirectory output("load-steps-python");
  const std::string python = std::filesystem::path(ROBIN_EXAMPLES) / "../python/robin-subdomain-py";
  const ProcessOutcome run =
      run_tool("robin-run",
               {example("non_matching_blocks_steps.toml").string(), "--output",
                (output.path() / "run").string(), "--server-executable",
                testing::tool("robin-subdomain").string(), "--server-executable", python},
               output.path(), 300.0);
  ASSERT_EQ(run.exit, "exited with status 0") << run.errors;
  for (int step = 1; step <= 3; ++step) {
    const auto contact = read_csv(output.path() / "run" / step_directory(step, 3) / "contact.csv");
    const double factor = step == 1 ? 0.5 : step == 2 ? 1.0 : 2.0;
    EXPECT_LE(largest_relative_difference(numbers(contact.at("pressure")),
                                          factor * exact_patch_pressure()),
              1e-8)
        << "step " << step;
  }
}

TEST(LoadStepsService, AProtocol20ServerIsRefusedForASteppedCase) {
  const TemporaryDirectory logs("load-steps-version");
  ServerLaunchOptions options = testing::server_options(logs.path());
  options.extra_arguments = {"--protocol-minor", "0"};
  SubdomainServer server1("lower", options);
  SubdomainServer server2("upper", testing::server_options(logs.path()));
  server1.await_listening();
  server2.await_listening();
  const CaseDefinition definition = read_case_file(example("non_matching_blocks_steps.toml"));
  RemotePortOptions port_options;
  port_options.request_timeout_seconds = 30.0;
  RemotePort port1(server1.endpoint(), "lower", port_options);
  RemotePort port2(server2.endpoint(), "upper", port_options);
  try {
    run_coupled_case(definition, {&port1, &port2}, definition.coupling);
    FAIL() << "a stepped case ran on a protocol 2.0 server";
  } catch (const PortError& error) {
    const std::string message = error.what();
    std::cout << message << "\n";
    EXPECT_NE(message.find("server " + server1.endpoint()), std::string::npos) << message;
    EXPECT_NE(message.find("speaks protocol 2.0"), std::string::npos) << message;
    EXPECT_NE(message.find("this coordinator speaks 2." + std::to_string(protocol::protocol_minor)),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("[loading]"), std::string::npos) << message;
  }
  port1.end_run();
  port2.end_run();
}

bool passes(const ConformanceReport& report, const std::string& name) {
  for (const ConformanceCheck& check : report.checks) {
    if (check.name == name) return check.passed;
  }
  return false;
}

bool has_check(const ConformanceReport& report, const std::string& name) {
  for (const ConformanceCheck& check : report.checks) {
    if (check.name == name) return true;
  }
  return false;
}

TEST(LoadStepsService, ConformanceCheckerJudgesSetLoadFactor) {
  const TemporaryDirectory logs("load-steps-conformance");
  ConformanceOptions options;
  options.oversized_message_bytes = 1 << 20;
  for (const bool python : {false, true}) {
    SubdomainServer server(python ? "python" : "reference",
                           python ? testing::python_server_options(logs.path())
                                  : testing::server_options(logs.path()));
    server.await_listening();
    const ConformanceReport report = check_server(server.endpoint(), options);
    EXPECT_TRUE(report.conforms()) << format_report(report);
    for (const char* name : {"load_factor", "load_factor_non_finite", "load_factor_absurd",
                             "load_factor_scaling", "load_factor_before_setup"}) {
      EXPECT_TRUE(passes(report, name)) << name << (python ? " (Python server)" : "");
    }
  }
  // A server of protocol 2.0 is judged only on refusing the request.
  ServerLaunchOptions launch = testing::server_options(logs.path());
  launch.extra_arguments = {"--protocol-minor", "0"};
  SubdomainServer old("old", launch);
  old.await_listening();
  const ConformanceReport report = check_server(old.endpoint(), options);
  EXPECT_TRUE(report.conforms()) << format_report(report);
  EXPECT_TRUE(passes(report, "load_factor_unsupported"));
  EXPECT_FALSE(has_check(report, "load_factor_scaling"));
}

}  // namespace
}  // namespace robin
