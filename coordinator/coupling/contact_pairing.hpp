#pragma once
// Node-to-node pairing of the two contact boundaries (matching meshes on the contact zone).
// For each pair i: the body-1 normal n1_i (unit; body 2 uses n2_i = -n1_i), taken as the
// normalised average of body 1's outward normal and minus body 2's; the initial normal gap
//   d_i = (x2_i - x1_i) . n1_i + g0(x1_i)
// and the boundary weight m_i (average of both sides). A pair whose normal displacement is
// prescribed on either side by Dirichlet conditions is excluded (reported in `excluded`).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "coupling/gap_function.hpp"
#include "numerics/body_solver.hpp"

namespace robin {

struct ContactPair {
  int node1 = -1;                                      // mesh node index in body 1
  int node2 = -1;                                      // mesh node index in body 2
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // body-1 node
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();    // n1 (unit, outward from body 1)
  double gap = 0.0;                                    // d_i (length)
  double weight = 0.0;                                 // m_i (length)
};

struct ContactPairing {
  std::vector<ContactPair> pairs;
  std::vector<std::string> excluded;  // one line per excluded pair, with the reason

  std::size_t size() const { return pairs.size(); }
  /// The assignment for body 0 (normals n1) or body 1 (normals -n1).
  ContactAssignment assignment(int body_index) const;
  Eigen::VectorXd gaps() const;
  Eigen::VectorXd weights() const;
};

/// Pairs the two interfaces. `gap` may be null. A body-1 node matches the body-2 node whose
/// offset from it is, up to the normal component, shorter than relative_tolerance times the
/// shortest contact edge; every node of both sides must be matched. Throws InputError naming
/// the first unmatched node (body, mesh node tag, coordinates).
ContactPairing pair_contact_nodes(const InterfaceDescription& body1, const std::string& name1,
                                  const InterfaceDescription& body2, const std::string& name2,
                                  const GapFunction* gap, double relative_tolerance);

}  // namespace robin
