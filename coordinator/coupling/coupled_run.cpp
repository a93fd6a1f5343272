#include "coupling/coupled_run.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <future>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "coupling/checkpoint_encoding.hpp"
#include "coupling/interface_outputs.hpp"
#include "coupling/iteration_checkpoint.hpp"
#include "coupling/local_problem.hpp"
#include "coupling/mesh_arrivals.hpp"
#include "coupling/step_outputs.hpp"

namespace robin {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

PortTimings difference(const PortTimings& later, const PortTimings& earlier) {
  return {later.compute_seconds - earlier.compute_seconds,
          later.round_trip_seconds - earlier.round_trip_seconds,
          later.bytes_sent - earlier.bytes_sent, later.bytes_received - earlier.bytes_received};
}

std::vector<PortTimings> differences(const std::vector<PortTimings>& later,
                                     const std::vector<PortTimings>& earlier) {
  std::vector<PortTimings> result;
  for (std::size_t alpha = 0; alpha < later.size(); ++alpha) {
    result.push_back(difference(later[alpha], earlier.at(alpha)));
  }
  return result;
}

/// "both bodies" or "the 4 bodies", for progress lines.
std::string every_body(const RecoverablePorts& ports) {
  return ports.body_count() == 2 ? "both bodies"
                                 : "the " + std::to_string(ports.body_count()) + " bodies";
}

/// A server's refusal of a body's setup, with the place in the case file it is about: a body
/// left with a rigid motion (SINGULAR_BODY) names the body's Dirichlet conditions, anything else
/// (a resource limit, an unusable material) the body's [[body]] table.
std::string in_body_case(const BodyCase& body, const std::string& message) {
  std::string where = body.context;
  if (message.find("SINGULAR_BODY") != std::string::npos) {
    std::string dirichlet;
    for (const BoundaryReference& reference : body.boundary_references) {
      if (reference.field.find(".dirichlet[") == std::string::npos) continue;
      dirichlet += (dirichlet.empty() ? "" : ", ") + reference.location + " " + reference.field;
    }
    if (!dirichlet.empty()) where += " (its Dirichlet conditions: " + dirichlet + ")";
  } else if (!body.mesh_context.empty()) {
    where = body.mesh_context.substr(0, body.mesh_context.rfind(": "));  // "case.toml:27: body 'x'"
  }
  return where + ": " + message;
}

/// A warning goes to observer.warning, or to observer.stage when there is none.
void report_warning(const RunObserver& observer, const std::string& text) {
  if (observer.warning) {
    observer.warning(text);
  } else if (observer.stage) {
    observer.stage(text);
  }
}

void report_stage(const RunObserver& observer, const std::string& text) {
  if (observer.stage) observer.stage(text);
}

std::string message_of(const std::exception_ptr& failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const std::exception& error) {
    return error.what();
  } catch (...) {
    return "unknown error";
  }
}

/// Calls `request(port, alpha)` on every port concurrently and returns the results in port
/// order. After all have finished, a failure of one body is rethrown as it is; failures of
/// several bodies become one PortError carrying every message (each names its server, body and
/// step).
template <typename Request>
auto on_every_port(const std::vector<SubdomainPort*>& ports, Request request) {
  using Result = decltype(request(*ports[0], 0));
  std::vector<std::future<Result>> others;
  for (std::size_t alpha = 1; alpha < ports.size(); ++alpha) {
    others.push_back(std::async(std::launch::async, [&, alpha] {
      return request(*ports[alpha], static_cast<int>(alpha));
    }));
  }
  std::vector<Result> results(ports.size());
  std::vector<std::exception_ptr> failures(ports.size());
  for (std::size_t alpha = 0; alpha < ports.size(); ++alpha) {
    try {
      results[alpha] = alpha == 0 ? request(*ports[0], 0) : others[alpha - 1].get();
    } catch (...) {
      failures[alpha] = std::current_exception();
    }
  }
  std::vector<std::exception_ptr> failed;
  for (const std::exception_ptr& failure : failures) {
    if (failure) failed.push_back(failure);
  }
  if (failed.size() == 1) std::rethrow_exception(failed.front());
  if (failed.size() > 1) {
    std::string message = message_of(failed.front());
    for (std::size_t k = 1; k < failed.size(); ++k) message += "\n  and " + message_of(failed[k]);
    throw PortError(message);
  }
  return results;
}

/// The displacement of the output node nearest to `point` (node ids are opaque to the
/// coordinator, positions are not); zero when the fields carry no displacement.
Eigen::Vector3d displacement_near(const BodyOutput& output, const Eigen::Vector3d& point) {
  const int dimension = output.mesh.dimension;
  const OutputField* displacement = nullptr;
  for (const OutputField& field : output.point_fields) {
    if (field.name == "displacement" && field.components == dimension) displacement = &field;
  }
  if (displacement == nullptr || output.mesh.nodes.empty()) return Eigen::Vector3d::Zero();
  std::size_t nearest = 0;
  for (std::size_t k = 1; k < output.mesh.nodes.size(); ++k) {
    if ((output.mesh.nodes[k] - point).squaredNorm() <
        (output.mesh.nodes[nearest] - point).squaredNorm())
      nearest = k;
  }
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  const std::size_t first = static_cast<std::size_t>(dimension) * nearest;
  for (int component = 0; component < dimension; ++component) {
    value[component] = displacement->values[first + static_cast<std::size_t>(component)];
  }
  return value;
}

/// The excluded pairs in the final state, scaled by the included pairs' gaps and traces.
ExcludedPairClearance excluded_clearance(const CoupledRunResult& result) {
  const auto displacement_of = [&](int body, const ContactPair& pair, int side) {
    return displacement_near(result.outputs.at(static_cast<std::size_t>(body)),
                             side == 0 ? pair.position : pair.position2);
  };
  return graph_excluded_clearance(result.coupling, result.iteration.state, displacement_of);
}

/// The start of load step `factor` from the fixed points of the steps before it: the linear
/// extrapolation x_p + (t - t_p) / (t_p - t_q) (x_p - x_q) through the last two, (t_q, x_q) and
/// (t_p, x_p), or x_p alone when there is one or the factors coincide. In a fixed active set the
/// fixed point is an affine function of the load factor (e = t e_1, d fixed), so the
/// extrapolation is exact there; when the contact zone changes it is a prediction.
Eigen::VectorXd predicted_start(const std::vector<std::pair<double, Eigen::VectorXd>>& points,
                                double factor) {
  const auto& [last_factor, last] = points.back();
  if (points.size() < 2) return last;
  const auto& [before_factor, before] = points[points.size() - 2];
  if (last_factor == before_factor || before.size() != last.size()) return last;
  return last + ((factor - last_factor) / (last_factor - before_factor)) * (last - before);
}

/// Whether the first step's start, the scheme's iterate for the initial obstacle d, is the
/// fixed point at load factor 0: with no load and no prescribed displacement u = 0, so for
/// "robin", "robin-constant" and "dirichlet-neumann" H(x) = d when no gap is negative.
bool start_is_the_unloaded_fixed_point(const CouplingOptions& options,
                                       const CouplingProblem& problem) {
  const bool obstacle_scheme = options.algorithm == CouplingAlgorithm::robin ||
                               options.algorithm == CouplingAlgorithm::robin_constant ||
                               options.algorithm == CouplingAlgorithm::dirichlet_neumann;
  return obstacle_scheme && options.initial_obstacle == InitialObstacle::gap &&
         problem.gaps.size() > 0 && problem.gaps.minCoeff() >= 0.0;
}

/// The timings of every body's ports (the replaced ones included).
std::vector<PortTimings> port_timings(const RecoverablePorts& ports) {
  std::vector<PortTimings> timings;
  for (int alpha = 0; alpha < ports.body_count(); ++alpha) timings.push_back(ports.timings(alpha));
  return timings;
}

/// The iteration on the recoverable ports: after a lost server, it continues from its last
/// checkpoint (or `resume`, or starts again when there is none). `catch_up` brings the servers'
/// contact warm start to where the iteration found it (the load steps before it) and is called
/// before every attempt after a lost server, and before the first when `behind`. The iteration's
/// last checkpoint goes to `last` when it is not null.
RobinResult recoverable_iteration(RecoverablePorts& ports, const CouplingProblem& problem,
                                  const CouplingOptions& options,
                                  const Eigen::VectorXd* initial_iterate,
                                  const IterationCheckpoint* resume,
                                  const std::function<void(const IterationCheckpoint&)>& observe,
                                  const RunObserver& observer,
                                  const std::function<void()>& catch_up = {}, bool behind = false,
                                  std::optional<IterationCheckpoint>* last = nullptr) {
  std::optional<IterationCheckpoint> latest;
  if (resume != nullptr) latest = *resume;
  IterationContinuation loop;
  loop.checkpoint = [&](const IterationCheckpoint& checkpoint) {
    latest = checkpoint;
    if (observe) observe(checkpoint);
  };
  bool first_attempt = true;
  RobinResult result = ports.run([&] {
    if (catch_up && (behind || !first_attempt)) catch_up();
    first_attempt = false;
    const IterationCheckpoint* start = nullptr;
    std::optional<IterationCheckpoint> from;  // a copy: `latest` changes as the loop goes on
    if (latest) {
      from = *latest;
      start = &*from;
      if (!start->stopped) {
        report_stage(observer, "continuing the iteration after iteration " +
                                   std::to_string(start->iteration) + " (checkpoint)");
      }
    }
    loop.resume = start;
    return run_robin_iteration(ports.ports(), problem, options, initial_iterate, loop,
                               observer.iteration);
  });
  if (last != nullptr) *last = std::move(latest);
  return result;
}

/// Where the fields of load step `step` of `count` go (0: a run without load steps): see
/// RunContinuation::server_write_directory.
FieldsDestination fields_destination(const RunContinuation& continuation,
                                     const GraphCoupling& coupling, int step, std::size_t count) {
  FieldsDestination destination;
  if (continuation.server_write_directory.empty()) return destination;
  destination.write_directory = continuation.server_write_directory;
  if (step > 0) destination.write_directory /= step_directory(step, count);
  destination.omit_fields = true;
  for (const ContactPairing& pairing : coupling.pairings) {
    if (!pairing.excluded_pairs.empty()) destination.omit_fields = false;
  }
  return destination;
}

/// Every body's fields for the iteration's contact forces.
std::vector<BodyOutput> collect_fields(RecoverablePorts& ports, const RobinResult& iteration,
                                       const FieldsDestination& destination) {
  return ports.run([&] {
    return on_every_port(ports.ports(), [&](SubdomainPort& port, int alpha) {
      return port.fields(iteration.state.bodies[static_cast<std::size_t>(alpha)].contact_force,
                         destination);
    });
  });
}

/// Only the contact solves of the iterations at `iterates` (x_1, x_2, ...) of a run of the
/// iteration with `options` on `problem`, results discarded: the servers' contact warm start
/// after them is the one that run left (CouplingScheme::repeat_contact_solves). Throws PortError
/// as the iteration does.
void repeat_contact_solves(const std::vector<SubdomainPort*>& ports, const CouplingProblem& problem,
                           const CouplingOptions& options,
                           const std::vector<Eigen::VectorXd>& iterates) {
  if (iterates.empty()) return;
  const std::unique_ptr<CouplingScheme> scheme = make_coupling_scheme(options, ports, problem);
  for (std::size_t index = 0; index < iterates.size(); ++index) {
    scheme->repeat_contact_solves(iterates[index], static_cast<int>(index) + 1);
  }
}

/// Sets the load factor of every body (and of their replacements).
void set_load_factor(RecoverablePorts& ports, double factor) {
  ports.run([&] {
    on_every_port(ports.ports(), [&](SubdomainPort& port, int) {
      port.set_load_factor(factor);
      return 0;
    });
  });
  ports.load_factor_set(factor);
}

/// Checks that the checkpointed load steps are those of `loading`; throws CheckpointFormatError.
void check_resumed_steps(const LoadingOptions& loading,
                         const std::vector<LoadStepCheckpoint>& steps) {
  if (steps.size() >= loading.factors.size()) {
    throw CheckpointFormatError("the checkpoint has " + std::to_string(steps.size()) +
                                " completed load steps, the case " +
                                std::to_string(loading.factors.size()));
  }
  for (std::size_t k = 0; k < steps.size(); ++k) {
    if (steps[k].step != static_cast<int>(k + 1) || steps[k].factor != loading.factors[k] ||
        steps[k].iteration.status != IterationStatus::converged) {
      throw CheckpointFormatError("the checkpoint's load step " + std::to_string(k + 1) +
                                  " is not the case's, or did not converge");
    }
  }
}

/// The load steps of a case with [loading] on ports whose contact is assigned (see
/// run_coupled_case). Fills result.steps and, from the last step computed, result.iteration,
/// outputs and iteration_port_timings; result.excluded_clearance is the worst over the steps.
/// With continuation.resume, the steps before it are taken from continuation.resume_steps
/// (their fields collected again) and the step it belongs to continues after it.
void run_load_steps(const LoadingOptions& loading, RecoverablePorts& ports,
                    const CouplingOptions& options, const RunObserver& observer,
                    const RunContinuation& continuation, CoupledRunResult& result) {
  const std::size_t count = loading.factors.size();
  static const std::vector<LoadStepCheckpoint> none;
  const std::vector<LoadStepCheckpoint>& resumed =
      continuation.resume == nullptr || continuation.resume_steps == nullptr
          ? none
          : *continuation.resume_steps;
  if (continuation.resume != nullptr) check_resumed_steps(loading, resumed);
  // The fixed points (restart iterates) of the steps so far, with their load factors.
  std::vector<std::pair<double, Eigen::VectorXd>> points;
  // The load factors and iterates of the steps so far: their contact solves, repeated in order
  // on servers that have not seen them, give the servers the uninterrupted run's warm start.
  std::vector<std::pair<double, std::vector<Eigen::VectorXd>>> solved;
  // Whether the servers' contact warm start lacks the steps so far: after a resume, or once a
  // server was replaced (result.recoveries grew) since the last step's iteration.
  bool behind = continuation.resume != nullptr;
  std::size_t recoveries = result.recoveries.size();
  const auto catch_up = [&](double factor) {
    return [&, factor] {
      report_stage(observer, "repeating the contact solves of the " +
                                 std::to_string(solved.size()) +
                                 " load steps before (the servers' warm start)");
      for (const auto& [earlier, iterates] : solved) {
        set_load_factor(ports, earlier);
        repeat_contact_solves(ports.ports(), result.coupling.problem, options, iterates);
      }
      set_load_factor(ports, factor);
    };
  };
  for (std::size_t k = 0; k < count; ++k) {
    const auto step_start = Clock::now();
    LoadStepResult step;
    step.step = static_cast<int>(k + 1);
    step.factor = loading.factors[k];
    step.warm_started = loading.warm_start && !points.empty();
    const bool done_before = k < resumed.size();  // completed before the checkpoint
    const IterationCheckpoint* resume =
        done_before ? &resumed[k].iteration : (k == resumed.size() ? continuation.resume : nullptr);
    std::ostringstream stage;
    stage << "load step " << step.step << "/" << count << ": load factor " << step.factor
          << (step.warm_started ? ", starting from the previous steps" : "")
          << (done_before ? " (completed before the checkpoint: collecting its fields)" : "");
    report_stage(observer, stage.str());
    const std::vector<PortTimings> before = port_timings(ports);
    set_load_factor(ports, step.factor);
    const std::vector<PortTimings> before_iteration = port_timings(ports);
    const Eigen::VectorXd start =
        step.warm_started ? predicted_start(points, step.factor) : Eigen::VectorXd();
    const auto iteration_start = Clock::now();
    std::optional<IterationCheckpoint> last;
    if (done_before) {
      step.iteration = recoverable_iteration(ports, result.coupling.problem, options, nullptr,
                                             resume, {}, observer, {}, false, &last);
    } else {
      // a loop resumed after it stopped makes no request: the servers stay behind
      const bool stopped = resume != nullptr && resume->stopped;
      behind = behind || result.recoveries.size() != recoveries;
      step.iteration = recoverable_iteration(
          ports, result.coupling.problem, options, step.warm_started ? &start : nullptr, resume,
          continuation.checkpoint, observer,
          solved.empty() ? std::function<void()>() : catch_up(step.factor), behind && !stopped,
          &last);
      behind = stopped;
      recoveries = result.recoveries.size();
    }
    result.profile.iterations_seconds += seconds_since(iteration_start);
    result.iteration_port_timings = differences(port_timings(ports), before_iteration);
    report_stage(observer, "collecting the fields of " + every_body(ports) + " (load step " +
                               std::to_string(step.step) + ")");
    const auto fields_start = Clock::now();
    step.outputs = collect_fields(
        ports, step.iteration,
        fields_destination(continuation, result.coupling, step.step, loading.factors.size()));
    result.profile.fields_seconds += seconds_since(fields_start);
    result.iteration = step.iteration;
    result.outputs = step.outputs;
    step.excluded_clearance = excluded_clearance(result);
    step.port_timings = differences(port_timings(ports), before);
    step.seconds = done_before ? resumed[k].seconds : seconds_since(step_start);
    if (result.steps.empty() || step.excluded_clearance.relative_penetration >
                                    result.excluded_clearance.relative_penetration) {
      result.excluded_clearance = step.excluded_clearance;
    }
    if (points.empty() && start_is_the_unloaded_fixed_point(options, result.coupling.problem)) {
      points.emplace_back(0.0, step.iteration.initial_iterate);
    }
    points.emplace_back(step.factor, step.iteration.restart_iterate);
    if (last) solved.emplace_back(step.factor, last->iterates);
    const bool converged = step.iteration.status == IterationStatus::converged;
    if (!done_before && continuation.step_completed && last) {
      LoadStepCheckpoint completed{step.step, step.factor, step.warm_started, step.seconds,
                                   std::move(*last)};
      completed.iteration.acceleration = nlohmann::json();  // a completed step does not go on
      continuation.step_completed(completed);
    }
    result.steps.push_back(std::move(step));
    if (!converged) {
      report_stage(observer, "load step " + std::to_string(k + 1) +
                                 " did not converge: the later steps are not computed");
      break;
    }
  }
}

/// Sets every body up (each once, also across recoveries), each as soon as its mesh has
/// arrived; a body whose mesh never arrives (the loading was abandoned) is skipped.
void set_up_bodies(RecoverablePorts& ports, const CaseDefinition& loaded, MeshArrivals& arrivals) {
  ports.run([&] {
    on_every_port(ports.ports(), [&](SubdomainPort& port, int alpha) {
      if (ports.interface(alpha)) return 0;
      if (!arrivals.wait(static_cast<std::size_t>(alpha))) return 0;
      const BodyCase& body = loaded.bodies[static_cast<std::size_t>(alpha)];
      try {
        ports.interface(alpha) = port.setup(body, loaded.solver);
      } catch (const PortError& error) {
        throw PortError(in_body_case(body, error.what()));
      }
      return 0;
    });
  });
}

/// Reads or meshes every body's mesh into `loaded` and sets the bodies up, each body's setup
/// beginning as soon as its mesh is in (while the others are still read or meshed); returns
/// their interfaces. The meshes are loaded on a thread of their own, the setups (and a
/// recovery's restarted servers, which end with the thread that started them) stay on the
/// calling thread. `report` tells people, from either thread. A failure of the loading is
/// thrown after the setups already begun have ended.
std::vector<InterfaceDescription> load_and_set_up_bodies(
    RecoverablePorts& ports, CaseDefinition& loaded,
    const std::function<void(const std::string&)>& report, CoupledRunResult& result) {
  const auto start = Clock::now();
  MeshArrivals arrivals(loaded.bodies.size());
  std::future<void> loading = std::async(std::launch::async, [&] {
    try {
      load_meshes(loaded, [&](std::size_t body) {
        report("setting up body '" + loaded.bodies[body].definition.name +
               "' (assembly, factorization)");
        arrivals.arrive(body);
      });
    } catch (...) {
      arrivals.abandon();
      throw;
    }
  });
  try {
    set_up_bodies(ports, loaded, arrivals);
  } catch (...) {
    arrivals.abandon();  // a setup failed: the loading goes on only to its end
    loading.wait();
    throw;
  }
  loading.get();  // the loading's error, when it failed
  // the stages stay consecutive: meshing until the first setup began, setup from there
  const auto bodies_set_up = Clock::now();
  const auto first_setup = arrivals.first_arrival().value_or(start);
  result.meshing_seconds =
      std::chrono::duration<double>(arrivals.last_arrival().value_or(start) - start).count();
  result.profile.meshing_seconds = std::chrono::duration<double>(first_setup - start).count();
  result.profile.setup_seconds = std::chrono::duration<double>(bodies_set_up - first_setup).count();
  std::vector<InterfaceDescription> interfaces;
  for (int alpha = 0; alpha < ports.body_count(); ++alpha) {
    interfaces.push_back(*ports.interface(alpha));
  }
  return interfaces;
}

/// The contact rows of every interface from the servers' descriptions; errors name the file.
GraphCoupling couple_interfaces(const CaseDefinition& definition,
                                const std::vector<InterfaceDescription>& interfaces) {
  const std::unique_ptr<GapFunction> gap = make_gap_function(definition);
  return couple_contact_graph(interfaces, body_names(definition), interface_definitions(definition),
                              gap.get(), definition.contact, definition.solver.pairing_tolerance);
}

/// The iteration of a case without [loading], and its fields.
void run_single_solve(RecoverablePorts& recoverable, const CouplingOptions& options,
                      const RunObserver& observer, const RunContinuation& continuation,
                      CoupledRunResult& result) {
  const std::vector<PortTimings> before = port_timings(recoverable);
  const auto iteration_start = Clock::now();
  result.iteration = recoverable_iteration(recoverable, result.coupling.problem, options, nullptr,
                                           continuation.resume, continuation.checkpoint, observer);
  result.profile.iterations_seconds = seconds_since(iteration_start);
  result.iteration_port_timings = differences(port_timings(recoverable), before);
  report_stage(observer, "collecting the fields of " + every_body(recoverable));
  const auto fields_start = Clock::now();
  result.outputs = collect_fields(recoverable, result.iteration,
                                  fields_destination(continuation, result.coupling, 0, 0));
  result.profile.fields_seconds = seconds_since(fields_start);
  result.excluded_clearance = excluded_clearance(result);
}

}  // namespace

CoupledRunResult run_coupled_case(const CaseDefinition& definition,
                                  const std::vector<SubdomainPort*>& ports,
                                  const CouplingOptions& options, const RunObserver& observer,
                                  const RunContinuation& continuation) {
  const auto start = Clock::now();
  CoupledRunResult result;
  result.profile.launch_seconds = seconds_launched();
  result.options = options;
  const std::string bodies = definition.bodies.size() == 2
                                 ? std::string("both bodies")
                                 : "the " + std::to_string(definition.bodies.size()) + " bodies";
  report_stage(observer, "reading and meshing " + bodies);
  CaseDefinition loaded = definition;
  std::mutex observer_mutex;  // the meshes are loaded on a thread of their own
  RecoverablePorts recoverable(ports, loaded, continuation.replacement,
                               [&](const std::string& text) {
                                 const std::lock_guard<std::mutex> lock(observer_mutex);
                                 result.recoveries.push_back(text);
                                 report_warning(observer, text);
                               });
  result.interfaces = load_and_set_up_bodies(
      recoverable, loaded,
      [&](const std::string& text) {
        const std::lock_guard<std::mutex> lock(observer_mutex);
        report_stage(observer, text);
      },
      result);
  const auto coupling_start = Clock::now();
  result.coupling = couple_interfaces(definition, result.interfaces);
  result.coupling_seconds = seconds_since(coupling_start);
  result.profile.contact_coupling_seconds = result.coupling_seconds;
  for (const std::string& line : describe_interfaces(result.coupling, body_names(definition)))
    report_stage(observer, line);
  for (const std::string& line : excluded_pair_lines(result.coupling))
    report_warning(observer, line);
  for (const std::string& line : overlap_warnings(result.coupling)) report_warning(observer, line);
  const auto assignment_start = Clock::now();
  recoverable.run([&] {  // every body's at once: each server builds its interface operator
    on_every_port(recoverable.ports(), [&](SubdomainPort& port, int alpha) {
      port.assign_contact(result.coupling.operators[static_cast<std::size_t>(alpha)]);
      return 0;
    });
  });
  recoverable.contact_assigned(result.coupling.operators);
  result.profile.contact_assignment_seconds = seconds_since(assignment_start);
  result.setup_seconds = seconds_since(start);

  if (definition.loading.stepped()) {
    run_load_steps(definition.loading, recoverable, options, observer, continuation, result);
  } else {
    run_single_solve(recoverable, options, observer, continuation, result);
  }
  result.port_timings = port_timings(recoverable);
  for (int alpha = 0; alpha < recoverable.body_count(); ++alpha) {
    result.profile.bodies.push_back(recoverable.port(alpha).profile());
  }
  result.total_seconds = seconds_since(start);
  return result;
}

const ContactPairing& CoupledRunResult::pairing() const {
  if (coupling.pairings.size() != 1) {
    throw std::logic_error("CoupledRunResult::pairing: the case has " +
                           std::to_string(coupling.pairings.size()) + " contact interfaces");
  }
  return coupling.pairings.front();
}

int exit_code(IterationStatus status) {
  switch (status) {
    case IterationStatus::converged:
      return 0;
    case IterationStatus::max_iterations:
      return 3;
    case IterationStatus::diverged:
      return 4;
    case IterationStatus::stagnated:
      return 5;
  }
  return 1;
}

}  // namespace robin
