#include "coupling/graph_coupling.hpp"

#include "numerics/errors.hpp"
#include "numerics/interface_description.hpp"

namespace robin {
namespace {

ContactPairing couple_interface(const std::vector<InterfaceDescription>& bodies,
                                const std::vector<std::string>& names,
                                const InterfaceDefinition& interface, std::size_t index,
                                const GapFunction* gap, const ContactOptions& options,
                                double pairing_tolerance, bool single) {
  const std::string context = "contact interface " + std::to_string(index + 1) + " (body '" +
                              names.at(static_cast<std::size_t>(interface.body_a)) +
                              "' boundary '" + interface.boundary_a + "' against body '" +
                              names.at(static_cast<std::size_t>(interface.body_b)) +
                              "' boundary '" + interface.boundary_b + "'): ";
  const ContactOptions& contact = interface.contact ? *interface.contact : options;
  try {
    return discretize_contact(
        restrict_to_boundary(bodies.at(static_cast<std::size_t>(interface.body_a)),
                             interface.boundary_a),
        names[static_cast<std::size_t>(interface.body_a)],
        restrict_to_boundary(bodies.at(static_cast<std::size_t>(interface.body_b)),
                             interface.boundary_b),
        names[static_cast<std::size_t>(interface.body_b)], gap, contact, pairing_tolerance);
  } catch (const InputError& error) {
    if (single) throw;  // two bodies: the messages of discretize_contact, unchanged
    throw InputError(context + error.what());
  }
}

}  // namespace

GraphCoupling couple_contact_graph(const std::vector<InterfaceDescription>& bodies,
                                   const std::vector<std::string>& names,
                                   const std::vector<InterfaceDefinition>& interfaces,
                                   const GapFunction* gap, const ContactOptions& options,
                                   double pairing_tolerance) {
  GraphCoupling coupling;
  std::vector<ContactGraph::Edge> edges;
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    const InterfaceDefinition& interface = interfaces[k];
    const int count = static_cast<int>(bodies.size());
    if (interface.body_a < 0 || interface.body_a >= count || interface.body_b < 0 ||
        interface.body_b >= count || interface.body_a == interface.body_b) {
      throw InputError("contact interface " + std::to_string(k + 1) +
                       " must join two different bodies of the " + std::to_string(count));
    }
    coupling.pairings.push_back(couple_interface(bodies, names, interface, k, gap, options,
                                                 pairing_tolerance, interfaces.size() == 1));
    edges.push_back({interface.body_a, interface.body_b,
                     static_cast<Eigen::Index>(coupling.pairings.back().size())});
  }
  coupling.problem.graph = ContactGraph(static_cast<int>(bodies.size()), edges);
  // B^alpha: the rows of alpha's interfaces in interface order.
  std::vector<std::vector<ContactOperator>> parts(bodies.size());
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    parts[static_cast<std::size_t>(interfaces[k].body_a)].push_back(
        coupling.pairings[k].assignment(0));
    parts[static_cast<std::size_t>(interfaces[k].body_b)].push_back(
        coupling.pairings[k].assignment(1));
  }
  for (const std::vector<ContactOperator>& body_parts : parts) {
    std::vector<const ContactOperator*> pointers;
    for (const ContactOperator& part : body_parts) pointers.push_back(&part);
    coupling.operators.push_back(stack_operators(pointers));
  }
  std::vector<Eigen::VectorXd> gaps, weights, probes;
  for (const ContactPairing& pairing : coupling.pairings) {
    gaps.push_back(pairing.gaps());
    weights.push_back(pairing.weights());
    probes.push_back(short_wavelength_forces(pairing));
  }
  coupling.problem.gaps = concatenate(gaps);
  coupling.problem.weights = concatenate(weights);
  coupling.problem.probe_forces = concatenate(probes);
  for (const InterfaceDescription& body : bodies) {
    coupling.problem.rigid_modes.push_back(body.rigid_modes);
  }
  return coupling;
}

}  // namespace robin
