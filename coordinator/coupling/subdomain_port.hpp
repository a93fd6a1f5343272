#pragma once
// The coordinator's view of one subdomain (one body), independent of where it runs.
// Two implementations: InProcessPort (calls BodySolver directly) and RemotePort (speaks the
// protocol of proto/robin.proto to a server over ZeroMQ). The Robin iteration only sees this
// interface, so the same algorithm code runs in one process or across machines.
//
// Requests are split into start_* / finish_* so that the two bodies compute in parallel:
// the iteration starts a request on both ports, then finishes both. Every method throws
// PortError (naming the server, the body and the step) on failure, including deadlines.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "coupling/case_file.hpp"
#include "numerics/body_output.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

class PortError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CorrectionSolveResult {
  Eigen::VectorXd normal_trace;  // w_N
  double seconds = 0.0;          // compute time where the body lives
};

/// Time spent by a port, for the summary's split of the wall time.
struct PortTimings {
  double compute_seconds = 0.0;     // reported by the body (server compute)
  double round_trip_seconds = 0.0;  // request sent to reply decoded (remote); = compute in process
  long bytes_sent = 0;
  long bytes_received = 0;
};

/// Where one body's setup and fields went, stage by stage (summary.json "profile",
/// docs/outputs.md), in seconds of wall time. Stages measured where the body lives; a stage
/// that was not reported (a server of protocol 2.1 or older) is absent.
struct BodyProfile {
  /// mesh, assembly, ordering, factorization (SetupBody), interface operator (AssignContact),
  /// fields (FieldsRequest) of the latest such request.
  std::map<SetupStage, double> stages;
  /// The whole SetupBody request where the body lives: at least the sum of its stages.
  std::optional<double> setup_seconds;
  /// Moving the SetupBody request and its reply: encoding the body, plus the round trip less
  /// setup_seconds. Zero in process.
  std::optional<double> transfer_seconds;
  /// The process's peak resident set size in bytes, from the latest reply that reported it
  /// (protocol 2.5: setup, contact assignment, fields); absent when none did (an older server,
  /// in process).
  std::optional<std::uint64_t> peak_resident_bytes;
  /// "direct" or "multigrid": the solver the body was set up with (in process, the one it uses;
  /// through a server, the one the coordinator asked for, case file's "auto" resolved); empty
  /// when unknown.
  std::string linear_solver;
};

/// Where a body's fields file goes. By default the port returns the whole mesh and fields and
/// the coordinator writes the file; with `write_directory` the body's server writes
/// <body>.vtu there itself (FieldsRequest.write_directory: relative to the server's output
/// root) and returns its name in BodyOutput::written_file, and with `omit_fields` too its reply
/// leaves the mesh and fields out (protocol 2.5; an older server sends them anyway).
struct FieldsDestination {
  std::filesystem::path write_directory;
  bool omit_fields = false;
};

class SubdomainPort {
 public:
  virtual ~SubdomainPort() = default;
  /// "server tcp://host:port" or "in-process", for messages.
  virtual std::string describe() const = 0;
  /// Sends the body, whose mesh is loaded (load_meshes); returns its contact boundary. Throws
  /// PortError.
  virtual InterfaceDescription setup(const BodyCase& body, const SolverOptions& solver) = 0;
  /// Sends the body's contact constraint operator B. Throws PortError.
  virtual void assign_contact(const ContactOperator& contact) = 0;
  virtual void start_contact_solve(const Eigen::VectorXd& obstacle, int iteration) = 0;
  virtual ContactSolveResult finish_contact_solve() = 0;
  /// The correction w_N = F r. `relative_accuracy` 0 asks for the server's full accuracy; a
  /// value in (0, 1) says that the caller needs w_N only to that relative accuracy (the
  /// compliance probe), which an iterative inner solver may use to stop earlier.
  virtual void start_correction(const Eigen::VectorXd& interface_force, int iteration,
                                double relative_accuracy) = 0;
  virtual CorrectionSolveResult finish_correction() = 0;
  /// The Neumann solve of the Dirichlet-Neumann iteration: K u = f - B' lambda for a given
  /// nodal contact force lambda (pair order; compression positive); returns u_N = B u in
  /// normal_trace. Protocol 1.1, capability "neumann_solve". The default throws PortError: a
  /// port without the capability cannot run the Dirichlet-Neumann iteration.
  virtual void start_neumann_solve(const Eigen::VectorXd& contact_force, int iteration);
  virtual CorrectionSolveResult finish_neumann_solve();
  /// Quasi-static load steps (protocol 2.1, SetLoadFactor): scales every load and prescribed
  /// displacement of the body by `factor` relative to its definition, keeping the factor of K
  /// and F; later solves and fields answer for the new loads. Valid after setup(). Throws
  /// PortError, also for a server of protocol 2.0 (naming the server and both versions).
  virtual void set_load_factor(double factor) = 0;
  /// The body's fields for contact forces lambda (see FieldsDestination; a port that cannot
  /// have its body's file written elsewhere ignores `destination` and returns everything).
  virtual BodyOutput fields(const Eigen::VectorXd& contact_force,
                            const FieldsDestination& destination) = 0;
  /// Ends the run (the server stays up for the next one). Must not throw.
  virtual void end_run() noexcept = 0;
  /// Forgets a request started but not finished (its reply, if any, is discarded), so that the
  /// port can be used again after the other body's server failed mid-step. Must not throw.
  virtual void abandon_request() noexcept {}
  virtual const PortTimings& timings() const = 0;
  /// The stages of the latest setup, contact assignment and fields (empty before setup()).
  virtual const BodyProfile& profile() const = 0;
};

}  // namespace robin
