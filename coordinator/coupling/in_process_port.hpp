#pragma once
// A subdomain port that owns a BodySolver in this process (no transport). Requests are
// computed in start_*; finish_* returns the stored result.

#include <memory>

#include "coupling/subdomain_port.hpp"

namespace robin {

class InProcessPort final : public SubdomainPort {
 public:
  InProcessPort() = default;
  std::string describe() const override { return "in-process body '" + name_ + "'"; }
  InterfaceDescription setup(const BodyCase& body, const SolverOptions& solver) override;
  void assign_contact(const ContactOperator& contact) override;
  void start_contact_solve(const Eigen::VectorXd& obstacle, int iteration) override;
  ContactSolveResult finish_contact_solve() override;
  void start_correction(const Eigen::VectorXd& interface_force, int iteration,
                        double relative_accuracy) override;
  CorrectionSolveResult finish_correction() override;
  void start_neumann_solve(const Eigen::VectorXd& contact_force, int iteration) override;
  CorrectionSolveResult finish_neumann_solve() override;
  void set_load_factor(double factor) override;
  BodyOutput fields(const Eigen::VectorXd& contact_force,
                    const FieldsDestination& destination) override;
  void end_run() noexcept override;
  const PortTimings& timings() const override { return timings_; }
  const BodyProfile& profile() const override { return profile_; }

 private:
  BodySolver& body();
  std::string name_;
  std::unique_ptr<BodySolver> body_;
  MprgpParameters qp_;
  ContactSolveResult contact_result_;
  CorrectionSolveResult correction_result_;
  CorrectionSolveResult neumann_result_;
  PortTimings timings_;
  BodyProfile profile_;
};

}  // namespace robin
