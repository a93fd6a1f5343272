// CurveZMQ between real robin-subdomain processes and the coordinator (docs/security.md), on
// examples/two_blocks.toml over tcp://127.0.0.1:
//  - an encrypted run (two servers with their own key pairs, the coordinator's key on their
//    allow-lists) equals the in-process run (InProcessPort, no transport) to 1e-12 in contact
//    forces, normal traces and displacements, with the same iteration count;
//  - robin-coordinator with a key that is not on the allow-list exits 1 with a message naming
//    the server and saying that authentication was refused (not a deadline), the server logs
//    the refused key and address, stays up, and serves the next, authorised run (same answer);
//  - a coordinator without CURVE against a CURVE server, with the wrong server key, or with
//    CURVE against a server without it, fails the handshake with a message that says so;
//  - robin-run --curve writes the in-process run's contact.csv (to 1e-12), its servers log
//    CurveZMQ, and the keys it made for the run are removed;
//  - the conformance checker (--check-server) with the client keys passes a CURVE server; with
//    a key that is not on the allow-list it says at once that authentication was refused and
//    runs no further check (exit 1, no deadline);
//  - deploy/remote-servers.sh passes --server-arguments to its servers and the coordinator's
//    CURVE options through: the run is admitted and writes the in-process contact.csv.

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>

#include "coupling/coupled_run.hpp"
#include "coupling/in_process_port.hpp"
#include "coupling/result_files.hpp"
#include "curve_keys.hpp"
#include "remote/remote_port.hpp"
#include "remote_test_support.hpp"

namespace robin {
namespace {

using testing::example;
using testing::expect_same_interface_state;
using testing::run_tool;
using testing::server_options;
using testing::TemporaryDirectory;
using testing::vectors_close;

/// examples/two_blocks.toml with both meshes loaded (SubdomainPort::setup sends the mesh).
CaseDefinition two_blocks() {
  CaseDefinition definition = read_case_file(example("two_blocks.toml"));
  load_meshes(definition);
  return definition;
}

/// The in-process run of two_blocks.toml, computed once.
const CoupledRunResult& in_process_reference() {
  static const CoupledRunResult reference = [] {
    const CaseDefinition definition = two_blocks();
    InProcessPort body1, body2;
    CoupledRunResult result = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
    body1.end_run();
    body2.end_run();
    return result;
  }();
  return reference;
}

Eigen::VectorXd displacement(const BodyOutput& output) {
  for (const OutputField& field : output.point_fields) {
    if (field.name == "displacement") {
      return Eigen::Map<const Eigen::VectorXd>(field.values.data(),
                                               static_cast<Eigen::Index>(field.values.size()));
    }
  }
  ADD_FAILURE() << "no displacement field in body '" << output.body_name << "'";
  return {};
}

void expect_equal_to_in_process(const CoupledRunResult& remote) {
  const CoupledRunResult& reference = in_process_reference();
  ASSERT_EQ(reference.iteration.status, IterationStatus::converged) << reference.iteration.message;
  EXPECT_EQ(remote.iteration.status, IterationStatus::converged) << remote.iteration.message;
  EXPECT_EQ(remote.iteration.history.size(), reference.iteration.history.size());
  expect_same_interface_state(remote.iteration, reference.iteration, 1e-12,
                              "in-process run (CURVE transport)");
  for (int alpha = 0; alpha < 2; ++alpha) {
    EXPECT_TRUE(vectors_close(displacement(remote.outputs[alpha]),
                              displacement(reference.outputs[alpha]), 1e-12))
        << "body " << alpha + 1;
  }
}

std::string file_text(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

/// Key pairs in a private directory: "server1", "server2", "coordinator", "stranger" (written
/// as NAME.public and NAME.secret), and the allow-list "allowed" holding the coordinator's key.
class CurveKeyring {
 public:
  CurveKeyring() : directory_("curve-keys") {
    for (const char* name : {"server1", "server2", "coordinator", "stranger"}) {
      write_curve_key_files(directory_.path() / name, generate_curve_key_pair(), false);
    }
    std::ofstream(directory_.path() / "allowed")
        << "# the coordinator of the tests\n"
        << read_curve_public_key_file(file("coordinator.public")) << "\n";
  }
  std::filesystem::path file(const std::string& name) const { return directory_.path() / name; }
  CurveKeyPair pair(const std::string& name) const {
    return read_curve_secret_key_file(file(name + ".secret"));
  }
  /// What `client` needs to talk to `server`.
  CurveClientKeys client_keys(const std::string& client, const std::string& server) const {
    return {pair(server).public_key, pair(client)};
  }
  /// Launch options of a CURVE server with `server`'s key pair, admitting the coordinator.
  ServerLaunchOptions server_launch(const std::filesystem::path& logs,
                                    const std::string& server) const {
    ServerLaunchOptions options = server_options(logs);
    options.log_level = "info";  // the admissions and refusals are logged at info and warn
    options.extra_arguments = {"--curve-secret-key", file(server + ".secret").string(),
                               "--curve-allow", file("allowed").string()};
    options.curve_client = client_keys("coordinator", server);  // for the Shutdown request
    return options;
  }

 private:
  TemporaryDirectory directory_;
};

RemotePortOptions curve_port(const std::optional<CurveClientKeys>& keys) {
  RemotePortOptions options;
  options.request_timeout_seconds = 30.0;
  options.channel.curve = keys;
  return options;
}

/// Runs two_blocks.toml on running servers with the given client keys (unset: no CURVE).
CoupledRunResult run_on(const std::array<std::string, 2>& endpoints,
                        const std::array<std::optional<CurveClientKeys>, 2>& keys) {
  const CaseDefinition definition = two_blocks();
  RemotePort body1(endpoints[0], "lower", curve_port(keys[0]));
  RemotePort body2(endpoints[1], "upper", curve_port(keys[1]));
  CoupledRunResult result = run_coupled_case(definition, {&body1, &body2}, definition.coupling);
  body1.end_run();
  body2.end_run();
  return result;
}

/// The message of the PortError of a handshake with the server at `endpoint` with `keys`.
std::string handshake_failure(const std::string& endpoint,
                              const std::optional<CurveClientKeys>& keys) {
  const CaseDefinition definition = two_blocks();
  RemotePort port(endpoint, "lower", curve_port(keys));
  try {
    port.setup(definition.bodies[0], definition.solver);
  } catch (const PortError& error) {
    std::cout << error.what() << "\n";
    return error.what();
  }
  ADD_FAILURE() << "the handshake with " << endpoint << " succeeded";
  return "";
}

/// The failure did not come from a deadline (the 30 s request timeout).
void expect_not_a_deadline(const std::string& message) {
  EXPECT_EQ(message.find("no reply within"), std::string::npos) << message;
  EXPECT_EQ(message.find("could not send within"), std::string::npos) << message;
}

TEST(CurveTransport, EncryptedTcpRunEqualsInProcessRun) {
  const CurveKeyring keys;
  const TemporaryDirectory logs("curve-run");
  SubdomainServer server1("lower", keys.server_launch(logs.path(), "server1"));
  SubdomainServer server2("upper", keys.server_launch(logs.path(), "server2"));
  server1.await_listening();
  server2.await_listening();
  expect_equal_to_in_process(run_on(
      {server1.endpoint(), server2.endpoint()},
      {keys.client_keys("coordinator", "server1"), keys.client_keys("coordinator", "server2")}));
  const std::string log = file_text(server1.log_file());
  EXPECT_NE(log.find("CurveZMQ with public key " + keys.pair("server1").public_key),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("admitted a client from 127.0.0.1 (CURVE public key " +
                     keys.pair("coordinator").public_key + ")"),
            std::string::npos)
      << log;
}

TEST(CurveTransport, UnlistedCoordinatorIsRefusedAndTheServerServesTheNextRun) {
  const CurveKeyring keys;
  const TemporaryDirectory work("curve-refused");
  SubdomainServer server1("lower", keys.server_launch(work.path(), "server1"));
  SubdomainServer server2("upper", keys.server_launch(work.path(), "server1"));
  server1.await_listening();
  server2.await_listening();

  const testing::ProcessOutcome refused =
      run_tool("robin-coordinator",
               {example("two_blocks.toml").string(), "--output", (work.path() / "refused").string(),
                "--subdomain", server1.endpoint(), "--subdomain", server2.endpoint(), "--timeout",
                "30", "--curve-secret-key", keys.file("stranger.secret").string(),
                "--curve-server-key", keys.file("server1.public").string()},
               work.path(), 60.0);
  std::cout << refused.errors;
  EXPECT_EQ(refused.exit, "exited with status 1") << refused.errors;
  // The bodies are set up in parallel: the first refusal names its server.
  EXPECT_TRUE(refused.errors.find("server " + server1.endpoint() + " (body 'lower')") !=
                  std::string::npos ||
              refused.errors.find("server " + server2.endpoint() + " (body 'upper')") !=
                  std::string::npos)
      << refused.errors;
  EXPECT_NE(refused.errors.find("authentication refused by the server"), std::string::npos)
      << refused.errors;
  EXPECT_NE(
      refused.errors.find(keys.pair("stranger").public_key + " is not on the server's allow-list"),
      std::string::npos)
      << refused.errors;
  expect_not_a_deadline(refused.errors);

  const std::string logs = file_text(server1.log_file()) + file_text(server2.log_file());
  EXPECT_NE(logs.find("refused a client from 127.0.0.1: its CURVE public key " +
                      keys.pair("stranger").public_key + " is not on the allow-list " +
                      keys.file("allowed").string()),
            std::string::npos)
      << logs;
  EXPECT_EQ(server1.failure(), "");  // still running
  EXPECT_EQ(server2.failure(), "");
  expect_equal_to_in_process(run_on(
      {server1.endpoint(), server2.endpoint()},
      {keys.client_keys("coordinator", "server1"), keys.client_keys("coordinator", "server1")}));
}

TEST(CurveTransport, MismatchedSecurityFailsTheHandshakeWithAClearMessage) {
  const CurveKeyring keys;
  const TemporaryDirectory logs("curve-mismatch");
  SubdomainServer curve_server("lower", keys.server_launch(logs.path(), "server1"));
  SubdomainServer plain_server("upper", server_options(logs.path()));
  curve_server.await_listening();
  plain_server.await_listening();

  const std::string plain_client = handshake_failure(curve_server.endpoint(), std::nullopt);
  EXPECT_NE(plain_client.find("server " + curve_server.endpoint()), std::string::npos);
  EXPECT_NE(plain_client.find("step handshake"), std::string::npos) << plain_client;
  EXPECT_NE(plain_client.find("give --curve-secret-key and --curve-server-key"), std::string::npos)
      << plain_client;
  expect_not_a_deadline(plain_client);

  const std::string wrong_key =
      handshake_failure(curve_server.endpoint(), keys.client_keys("coordinator", "server2"));
  EXPECT_NE(wrong_key.find("the CurveZMQ handshake failed"), std::string::npos) << wrong_key;
  EXPECT_NE(wrong_key.find("is --curve-server-key this server's public key"), std::string::npos)
      << wrong_key;
  expect_not_a_deadline(wrong_key);

  const std::string curve_client =
      handshake_failure(plain_server.endpoint(), keys.client_keys("coordinator", "server1"));
  EXPECT_NE(curve_client.find("server " + plain_server.endpoint()), std::string::npos);
  EXPECT_NE(curve_client.find("--curve-secret-key"), std::string::npos) << curve_client;
  expect_not_a_deadline(curve_client);

  // Both servers go on serving the clients that match them.
  const CaseDefinition definition = two_blocks();
  for (const auto& [endpoint, client] :
       std::vector<std::pair<std::string, std::optional<CurveClientKeys>>>{
           {curve_server.endpoint(), keys.client_keys("coordinator", "server1")},
           {plain_server.endpoint(), std::nullopt}}) {
    RemotePort port(endpoint, "lower", curve_port(client));
    EXPECT_GT(port.setup(definition.bodies[0], definition.solver).node_ids.size(), 0u) << endpoint;
    port.end_run();
  }
}

/// contact.csv as numbers, one row per pair (the header line skipped).
std::vector<std::vector<double>> contact_rows(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  std::getline(file, line);
  while (std::getline(file, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

/// `contact_csv` equals the contact.csv of the in-process run, column by column, to 1e-12.
void expect_contact_csv_of_in_process_run(const std::filesystem::path& contact_csv) {
  const CoupledRunResult& reference = in_process_reference();
  const TemporaryDirectory expected("contact-csv-reference");
  write_contact_csv(expected.path() / "contact.csv", reference.pairing(),
                    two_body_interface_state(reference.iteration.state));
  const auto rows = contact_rows(contact_csv);
  const auto expected_rows = contact_rows(expected.path() / "contact.csv");
  ASSERT_EQ(rows.size(), expected_rows.size()) << contact_csv;
  ASSERT_FALSE(rows.empty());
  const std::size_t columns = expected_rows.front().size();  // pair,x,y,nx,ny,gap0,un1,...
  for (std::size_t column = 0; column < columns; ++column) {
    Eigen::VectorXd actual(static_cast<Eigen::Index>(rows.size()));
    Eigen::VectorXd wanted(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t row = 0; row < rows.size(); ++row) {
      ASSERT_EQ(rows[row].size(), columns);
      actual(static_cast<Eigen::Index>(row)) = rows[row][column];
      wanted(static_cast<Eigen::Index>(row)) = expected_rows[row][column];
    }
    EXPECT_TRUE(vectors_close(actual, wanted, 1e-12)) << "contact.csv column " << column;
  }
}

TEST(CurveTransport, RobinRunWithCurveWritesTheInProcessContactState) {
  const TemporaryDirectory output("robin-run-curve");
  const testing::ProcessOutcome outcome = run_tool("robin-run",
                                                   {example("two_blocks.toml").string(), "--output",
                                                    (output.path() / "out").string(), "--curve"},
                                                   output.path(), 120.0);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.errors;
  EXPECT_NE(outcome.errors.find("CurveZMQ with keys made for this run"), std::string::npos)
      << outcome.errors;
  for (const char* body : {"lower", "upper"}) {
    const std::string log =
        file_text(output.path() / "out" / "logs" / ("server-" + std::string(body) + ".log"));
    EXPECT_NE(log.find("CurveZMQ with public key"), std::string::npos) << log;
    EXPECT_NE(log.find("admitted a client from 127.0.0.1"), std::string::npos) << log;
    // The keys made for the run are gone: "admitting the 1 client key(s) of DIR/NAME.public)".
    const std::string marker = "client key(s) of ";
    const auto start = log.find(marker);
    ASSERT_NE(start, std::string::npos) << log;
    const auto end = log.find(')', start);
    const std::filesystem::path allow_list =
        log.substr(start + marker.size(), end - start - marker.size());
    EXPECT_FALSE(std::filesystem::exists(allow_list.parent_path())) << allow_list;
  }

  expect_contact_csv_of_in_process_run(output.path() / "out" / "contact.csv");
}

TEST(CurveTransport, ConformanceCheckerSpeaksCurve) {
  const CurveKeyring keys;
  const TemporaryDirectory work("curve-conformance");
  SubdomainServer server("lower", keys.server_launch(work.path(), "server1"));
  server.await_listening();
  const testing::ProcessOutcome outcome =
      run_tool("robin-coordinator",
               {"--check-server", server.endpoint(), "--max-message-size-probe", "1024",
                "--curve-secret-key", keys.file("coordinator.secret").string(),
                "--curve-server-key", keys.file("server1.public").string()},
               work.path(), 120.0);
  EXPECT_EQ(outcome.exit, "exited with status 0") << outcome.output << outcome.errors;
  EXPECT_NE(outcome.output.find("the server conforms"), std::string::npos) << outcome.output;

  const auto start = std::chrono::steady_clock::now();
  const testing::ProcessOutcome refused =
      run_tool("robin-coordinator",
               {"--check-server", server.endpoint(), "--timeout", "30", "--curve-secret-key",
                keys.file("stranger.secret").string(), "--curve-server-key",
                keys.file("server1.public").string()},
               work.path(), 60.0);
  EXPECT_LT(testing::seconds_since(start), 10.0);  // not one 30 s deadline
  EXPECT_EQ(refused.exit, "exited with status 1") << refused.output << refused.errors;
  EXPECT_NE(refused.output.find("FAIL hello: Hello: authentication refused by the server"),
            std::string::npos)
      << refused.output;
  EXPECT_NE(
      refused.output.find(keys.pair("stranger").public_key + " is not on the server's allow-list"),
      std::string::npos)
      << refused.output;
  EXPECT_NE(refused.output.find("FAIL setup_body: not checked: the connection was refused (see "
                                "check 'hello')"),
            std::string::npos)
      << refused.output;
  expect_not_a_deadline(refused.output);
  EXPECT_NE(refused.output.find("does not conform"), std::string::npos) << refused.output;
  EXPECT_EQ(server.failure(), "");  // still running
}

TEST(CurveTransport, RemoteServersScriptPassesTheCurveOptions) {
  const CurveKeyring keys;
  const TemporaryDirectory output("remote-servers-curve");
  ChildProcessOptions options;
  options.executable = "/bin/bash";
  options.arguments = {
      (std::filesystem::path(ROBIN_EXAMPLES).parent_path() / "deploy" / "remote-servers.sh")
          .string(),
      "--subdomain-binary",
      testing::tool("robin-subdomain").string(),
      "--coordinator-binary",
      testing::tool("robin-coordinator").string(),
      "--server-arguments",
      "--curve-secret-key " + keys.file("server1.secret").string() + " --curve-allow " +
          keys.file("allowed").string(),
      example("two_blocks.toml").string(),
      "--output",
      output.path().string(),
      "--curve-secret-key",
      keys.file("coordinator.secret").string(),
      "--curve-server-key",
      keys.file("server1.public").string()};
  const TemporaryDirectory errors_directory("remote-servers-curve-errors");
  options.log_file = errors_directory.path() / "remote-servers.stderr";  // not in the results
  ChildProcess process(options);
  while (process.read_line(ChildProcess::Clock::time_point::max())) {
  }
  EXPECT_TRUE(process.wait_for_exit(120.0));
  const std::string errors = file_text(options.log_file);
  EXPECT_EQ(process.exit_description(), "exited with status 0") << errors;
  for (const char* log : {"server-1.log", "server-2.log"}) {
    const std::string text = file_text(output.path() / "logs" / log);
    EXPECT_NE(text.find("admitted a client from 127.0.0.1 (CURVE public key " +
                        keys.pair("coordinator").public_key + ")"),
              std::string::npos)
        << text;
  }
  expect_contact_csv_of_in_process_run(output.path() / "contact.csv");
}

}  // namespace
}  // namespace robin
