#include "coupling/interface_outputs.hpp"

#include <algorithm>

namespace robin {

InterfaceSummary summarize_interface(const ContactPairing& pairing, const InterfaceState& state) {
  InterfaceSummary summary;
  const auto size = static_cast<Eigen::Index>(pairing.size());
  if (state.contact_force1.size() != size || state.contact_force2.size() != size) return summary;
  const Eigen::VectorXd mean = 0.5 * (state.contact_force1 + state.contact_force2);
  for (std::size_t i = 0; i < pairing.size(); ++i) {
    const double force = mean[static_cast<Eigen::Index>(i)];
    if (force > 0.0) ++summary.active_pairs;
    summary.largest_pressure = std::max(summary.largest_pressure, force / pairing.pairs[i].weight);
  }
  summary.resultant = contact_resultant(pairing, mean);
  return summary;
}

std::string contact_file_name(const ContactGraph& graph, const std::vector<std::string>& names,
                              std::size_t interface) {
  if (graph.interfaces().size() == 1) return "contact.csv";
  const GraphInterface& edge = graph.interfaces().at(interface);
  return "contact_" + std::to_string(interface + 1) + "_" +
         names.at(static_cast<std::size_t>(edge.body_a)) + "_" +
         names.at(static_cast<std::size_t>(edge.body_b)) + ".csv";
}

bool has_interface_state(const GraphCoupling& coupling, const CouplingState& state) {
  const ContactGraph& graph = coupling.problem.graph;
  if (static_cast<int>(state.bodies.size()) != graph.body_count()) return false;
  for (int alpha = 0; alpha < graph.body_count(); ++alpha) {
    const BodyInterfaceState& body = state.bodies[static_cast<std::size_t>(alpha)];
    const Eigen::Index rows = graph.body_rows(alpha);
    if (body.normal_trace.size() != rows || body.contact_force.size() != rows) return false;
  }
  return true;
}

std::vector<std::string> write_contact_files(const std::filesystem::path& directory,
                                             const GraphCoupling& coupling,
                                             const std::vector<std::string>& names,
                                             const CouplingState& state) {
  const ContactGraph& graph = coupling.problem.graph;
  std::vector<std::string> files;
  for (std::size_t k = 0; k < coupling.pairings.size(); ++k) {
    files.push_back(contact_file_name(graph, names, k));
    write_contact_csv(directory / files.back(), coupling.pairings[k],
                      interface_state(graph, state, k));
  }
  return files;
}

nlohmann::json interfaces_json(const GraphCoupling& coupling,
                               const std::vector<InterfaceDefinition>& interfaces,
                               const std::vector<std::string>& names, const CouplingState& state) {
  const ContactGraph& graph = coupling.problem.graph;
  nlohmann::json entries = nlohmann::json::array();
  for (std::size_t k = 0; k < coupling.pairings.size(); ++k) {
    const ContactPairing& pairing = coupling.pairings[k];
    const InterfaceDefinition& interface = interfaces.at(k);
    const std::string& name_a = names.at(static_cast<std::size_t>(interface.body_a));
    const std::string& name_b = names.at(static_cast<std::size_t>(interface.body_b));
    const InterfaceSummary summary = summarize_interface(pairing, interface_state(graph, state, k));
    entries.push_back(
        {{"bodies", {name_a, name_b}},
         {"boundaries", {interface.boundary_a, interface.boundary_b}},
         {"contact_discretization", describe_contact(pairing, name_a, name_b)},
         {"contact_pairs", pairing.size()},
         {"active_pairs", summary.active_pairs},
         {"largest_pressure", summary.largest_pressure},
         {"excluded_pairs", pairing.excluded},
         {"initial_overlap", overlap_warning(pairing)},
         {"contact_force_resultant", vector_json(summary.resultant, pairing.dimension)},
         {"file", contact_file_name(graph, names, k)}});
  }
  return entries;
}

std::vector<std::string> describe_interfaces(const GraphCoupling& coupling,
                                             const std::vector<std::string>& names) {
  const ContactGraph& graph = coupling.problem.graph;
  std::vector<std::string> lines;
  for (std::size_t k = 0; k < coupling.pairings.size(); ++k) {
    const GraphInterface& edge = graph.interfaces()[k];
    const std::string line =
        describe_contact(coupling.pairings[k], names.at(static_cast<std::size_t>(edge.body_a)),
                         names.at(static_cast<std::size_t>(edge.body_b)));
    lines.push_back(coupling.pairings.size() == 1
                        ? line
                        : "interface " + std::to_string(k + 1) + " ('" +
                              names[static_cast<std::size_t>(edge.body_a)] + "' / '" +
                              names[static_cast<std::size_t>(edge.body_b)] + "'): " + line);
  }
  return lines;
}

std::vector<std::string> excluded_pair_lines(const GraphCoupling& coupling) {
  std::vector<std::string> lines;
  for (const ContactPairing& pairing : coupling.pairings) {
    lines.insert(lines.end(), pairing.excluded.begin(), pairing.excluded.end());
  }
  return lines;
}

std::vector<std::string> overlap_warnings(const GraphCoupling& coupling) {
  std::vector<std::string> lines;
  for (const ContactPairing& pairing : coupling.pairings) {
    if (std::string overlap = overlap_warning(pairing); !overlap.empty()) {
      lines.push_back(std::move(overlap));
    }
  }
  return lines;
}

CouplingState monolithic_state(const ContactGraph& graph, const MonolithicResult& result) {
  CouplingState state;
  for (int alpha = 0; alpha < graph.body_count(); ++alpha) {
    BodyInterfaceState body;
    body.normal_trace = result.normal_traces.at(static_cast<std::size_t>(alpha));
    body.contact_force = graph.body_part(alpha, result.contact_force);
    body.correction = Eigen::VectorXd::Zero(body.normal_trace.size());
    body.obstacle = body.correction;
    state.bodies.push_back(std::move(body));
  }
  return state;
}

ExcludedPairClearance graph_excluded_clearance(const GraphCoupling& coupling,
                                               const CouplingState& state,
                                               const GraphPairDisplacement& displacement_of) {
  double scale = 0.0;
  for (const BodyInterfaceState& body : state.bodies) {
    if (body.normal_trace.size() > 0) {
      scale = std::max(scale, body.normal_trace.cwiseAbs().maxCoeff());
    }
  }
  for (const ContactPairing& pairing : coupling.pairings) {
    if (pairing.size() > 0) scale = std::max(scale, pairing.gaps().cwiseAbs().maxCoeff());
  }
  ExcludedPairClearance worst;
  const ContactGraph& graph = coupling.problem.graph;
  for (std::size_t k = 0; k < coupling.pairings.size(); ++k) {
    const GraphInterface& edge = graph.interfaces()[k];
    const auto of_interface = [&](int side, const ContactPair& pair) {
      return displacement_of(side == 0 ? edge.body_a : edge.body_b, pair, side);
    };
    const ExcludedPairClearance clearance =
        excluded_pair_clearance(coupling.pairings[k], of_interface, scale);
    if (clearance.relative_penetration > worst.relative_penetration) worst = clearance;
  }
  return worst;
}

}  // namespace robin
