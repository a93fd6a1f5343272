#include "coupling/port_recovery.hpp"

#include <utility>

namespace robin {

RecoverablePorts::RecoverablePorts(const std::array<SubdomainPort*, 2>& ports,
                                   const CaseDefinition& loaded, ServerReplacement replacement,
                                   std::function<void(const std::string&)> report)
    : ports_(ports),
      loaded_(loaded),
      replacement_(std::move(replacement)),
      report_(std::move(report)) {}

PortTimings RecoverablePorts::timings(int body) const {
  PortTimings sum = replaced_timings_[body];
  const PortTimings& current = ports_[body]->timings();
  sum.compute_seconds += current.compute_seconds;
  sum.round_trip_seconds += current.round_trip_seconds;
  sum.bytes_sent += current.bytes_sent;
  sum.bytes_received += current.bytes_received;
  return sum;
}

void RecoverablePorts::restore_body(int body) {
  SubdomainPort& port = *ports_[body];
  const std::string& name = loaded_.bodies[body].definition.name;
  if (report_) report_("setting body '" + name + "' up again on " + port.describe());
  interfaces_[body] = port.setup(loaded_.bodies[body], loaded_.solver);
  if (pairing_ != nullptr) port.assign_contact(pairing_->assignment(body));
  if (load_factor_) port.set_load_factor(*load_factor_);
}

void RecoverablePorts::recover(const PortError& error) {
  std::string failure = error.what();
  for (;;) {
    std::array<bool, 2> lost{false, false};
    if (replacement_) {
      for (int body = 0; body < 2; ++body) lost[body] = replacement_.lost(body);
    }
    if (!lost[0] && !lost[1]) throw PortError(failure);
    for (int body = 0; body < 2; ++body) {
      ports_[body]->abandon_request();
      // throws when the server cannot be replaced: the run fails with that message
      if (!lost[body]) continue;
      const PortTimings& old = ports_[body]->timings();
      PortTimings& sum = replaced_timings_[body];
      sum.compute_seconds += old.compute_seconds;
      sum.round_trip_seconds += old.round_trip_seconds;
      sum.bytes_sent += old.bytes_sent;
      sum.bytes_received += old.bytes_received;
      ports_[body] = replacement_.replace(body, failure);
    }
    try {
      for (int body = 0; body < 2; ++body) {
        if (lost[body]) {
          restore_body(body);
        } else if (pairing_ != nullptr) {
          ports_[body]->assign_contact(pairing_->assignment(body));
        }
      }
      return;
    } catch (const PortError& again) {  // lost again while being restored
      failure = again.what();
    }
  }
}

}  // namespace robin
