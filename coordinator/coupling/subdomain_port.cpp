#include "coupling/subdomain_port.hpp"

namespace robin {

void SubdomainPort::start_neumann_solve(const Eigen::VectorXd& /*contact_force*/,
                                        int /*iteration*/) {
  throw PortError(describe() +
                  ", step Neumann solve: this subdomain does not offer the Neumann solve "
                  "(protocol capability \"neumann_solve\", protocol 1.1); the Dirichlet-Neumann "
                  "algorithm needs it");
}

CorrectionSolveResult SubdomainPort::finish_neumann_solve() {
  throw PortError(describe() + ", step Neumann solve: no Neumann solve was started");
}

}  // namespace robin
