#include "coupling/in_process_port.hpp"

#include <chrono>

#include "numerics/errors.hpp"

namespace robin {

BodySolver& InProcessPort::body() {
  if (!body_) throw PortError(describe() + ": request before setup");
  return *body_;
}

InterfaceDescription InProcessPort::setup(const BodyCase& body_case, const SolverOptions& solver) {
  name_ = body_case.definition.name;
  qp_ = solver.qp;
  if (body_case.definition.mesh.node_count() == 0) {
    throw PortError(describe() + ": body '" + name_ + "' has no mesh (load_meshes first)");
  }
  const auto start = std::chrono::steady_clock::now();
  body_ =
      std::make_unique<BodySolver>(body_case.definition, body_solver_options(solver, body_case));
  const BodyTimings& timings = body_->timings();
  timings_.compute_seconds += timings.setup_seconds();
  profile_ = BodyProfile{};
  profile_.stages = {{SetupStage::assembly, timings.assembly_seconds},
                     {SetupStage::ordering, timings.ordering_seconds},
                     {SetupStage::factorization, timings.factorization_seconds}};
  profile_.setup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  profile_.transfer_seconds = 0.0;
  profile_.linear_solver = linear_solver_name(body_->linear_solver());
  return body_->contact_boundary();
}

void InProcessPort::assign_contact(const ContactOperator& contact) {
  body().assign_contact(contact);
  profile_.stages[SetupStage::interface_operator] = body().timings().interface_seconds;
}

void InProcessPort::start_contact_solve(const Eigen::VectorXd& obstacle, int /*iteration*/) {
  contact_result_ = body().solve_contact(obstacle, qp_);
  timings_.compute_seconds += contact_result_.seconds;
  timings_.round_trip_seconds += contact_result_.seconds;
}

ContactSolveResult InProcessPort::finish_contact_solve() {
  return contact_result_;
}

void InProcessPort::start_correction(const Eigen::VectorXd& interface_force, int /*iteration*/,
                                     double relative_accuracy) {
  const auto start = std::chrono::steady_clock::now();
  correction_result_.normal_trace = body().solve_correction(interface_force, relative_accuracy);
  correction_result_.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  timings_.compute_seconds += correction_result_.seconds;
  timings_.round_trip_seconds += correction_result_.seconds;
}

CorrectionSolveResult InProcessPort::finish_correction() {
  return correction_result_;
}

void InProcessPort::start_neumann_solve(const Eigen::VectorXd& contact_force, int /*iteration*/) {
  const auto start = std::chrono::steady_clock::now();
  neumann_result_.normal_trace = body().solve_neumann(contact_force);
  neumann_result_.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  timings_.compute_seconds += neumann_result_.seconds;
  timings_.round_trip_seconds += neumann_result_.seconds;
}

CorrectionSolveResult InProcessPort::finish_neumann_solve() {
  return neumann_result_;
}

void InProcessPort::set_load_factor(double factor) {
  try {
    body().set_load_factor(factor);
  } catch (const InputError& error) {
    throw PortError(describe() + ", step load factor: " + error.what());
  }
}

/// The body lives here: there is no server to write its file, the coordinator writes it.
BodyOutput InProcessPort::fields(const Eigen::VectorXd& contact_force,
                                 const FieldsDestination& /*destination*/) {
  const auto start = std::chrono::steady_clock::now();
  BodyOutput output = make_body_output(body(), contact_force);
  profile_.stages[SetupStage::fields] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return output;
}

void InProcessPort::end_run() noexcept {
  body_.reset();
}

}  // namespace robin
