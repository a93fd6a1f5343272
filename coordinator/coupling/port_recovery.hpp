#pragma once
// Recovery from a server lost in the middle of a coupled run (docs/outputs.md, "Checkpoint
// and resume"). The ports of the run and what a replacement server needs to reach the state
// of the lost one: the body's setup, the contact assignment once made, the load factor once
// set. A stage of the run (setup, contact assignment, the iteration, the fields) runs through
// run(): when it fails with a PortError and a server is lost, the server is replaced (by the
// caller's hook, which bounds the restarts and throws when there are none left), its body set
// up again when it had been set up (else the setup stage, run again, sets it up), and the stage
// runs again. The surviving port forgets its unfinished request.
//
// The iteration stage continues from its last checkpoint (coupled_run.cpp). The survivors'
// contact is assigned again, which resets their contact QP's warm start to zero as at the
// start of the iteration; the resumed iteration repeats the contact solves of the iterations
// before it on both servers, so that it runs as it would have.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "coupling/case_file.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/subdomain_port.hpp"

namespace robin {

/// The caller's hooks for lost servers; both empty: a lost server fails the run.
struct ServerReplacement {
  /// Whether the server of body `body` (0-based) is gone (its process ended, its connection
  /// dropped), after a step on it failed.
  std::function<bool(int body)> lost;
  /// A port to a new (or restarted) server for body `body`, told the failure that lost the old
  /// one. The caller owns the port. Throws PortError when the server cannot be replaced (no
  /// restarts left, no server back within the grace period), naming server, body and why.
  std::function<SubdomainPort*(int body, const std::string& failure)> replace;
  explicit operator bool() const { return lost && replace; }
};

class RecoverablePorts {
 public:
  /// `loaded` holds the bodies, whose meshes may still be arriving while the setup stage runs
  /// (load_meshes fills them in); it must outlive this object.
  /// `report` is told, for people, what was recovered.
  /// One port per body of `loaded`, in body order.
  RecoverablePorts(const std::vector<SubdomainPort*>& ports, const CaseDefinition& loaded,
                   ServerReplacement replacement, std::function<void(const std::string&)> report);

  SubdomainPort& port(int body) { return *ports_.at(static_cast<std::size_t>(body)); }
  int body_count() const { return static_cast<int>(ports_.size()); }
  /// The timings of body `body`'s ports: the current one's plus those of the ports it replaced.
  PortTimings timings(int body) const;
  const std::vector<SubdomainPort*>& ports() const { return ports_; }

  /// Runs `stage()` until it returns: after a PortError with a lost server, recover() and again.
  template <typename Stage>
  auto run(Stage stage) {
    for (;;) {
      try {
        return stage();
      } catch (const PortError& error) {
        recover(error);
      }
    }
  }

  /// The interface of body `body` once set up (by the setup stage or a recovery).
  std::optional<InterfaceDescription>& interface(int body) {
    return interfaces_.at(static_cast<std::size_t>(body));
  }
  /// Records that the contact is assigned, body alpha `operators[alpha]` (a replacement server
  /// gets the same assignment); `operators` must outlive this object.
  void contact_assigned(const std::vector<ContactOperator>& operators) { operators_ = &operators; }
  /// Records the load factor of the bodies (a replacement server gets it too).
  void load_factor_set(double factor) { load_factor_ = factor; }

 private:
  /// Replaces every lost server and restores its body; rethrows `error` when none is lost or
  /// there are no hooks.
  void recover(const PortError& error);
  void restore_body(int body);

  std::vector<SubdomainPort*> ports_;
  std::vector<PortTimings> replaced_timings_;  // summed over the replaced ports
  const CaseDefinition& loaded_;
  ServerReplacement replacement_;
  std::function<void(const std::string&)> report_;
  std::vector<std::optional<InterfaceDescription>> interfaces_;
  const std::vector<ContactOperator>* operators_ = nullptr;
  std::optional<double> load_factor_;
};

}  // namespace robin
