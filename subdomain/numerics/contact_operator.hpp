#pragma once
// The contact constraint operator B of one body: B u <= g, one row per constraint (the
// multiplier space), columns the body's displacement components. Stored in compressed rows over
// (node, component) pairs:
//   (B u)_j = sum over k in [row_offsets[j], row_offsets[j+1]) of values[k] u_c(nodes[k]),
// c = components[k]. Node-to-node contact is the special case of one row per contact node with
// the components of its unit normal; mortar coupling gives rows with several nodes. Each row has
// a weight m_j > 0 (pressure_j = lambda_j / m_j): the boundary weight of its node for
// node-to-node rows, the mortar weight m_j = sum_k D_jk for dual multipliers (D_jj on linear
// segments and faces; coupling/mortar_rows.hpp).

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

namespace robin {

struct ContactOperator {
  std::vector<std::size_t> row_offsets{0};
  std::vector<int> nodes;       // mesh node index of each entry
  std::vector<int> components;  // 0 (x), 1 (y) or 2 (z, solid bodies) of each entry
  std::vector<double> values;   // coefficient of each entry (dimensionless)
  std::vector<double> weights;  // m_j of each row (length)

  int row_count() const { return static_cast<int>(row_offsets.size()) - 1; }
  std::size_t entry_count() const { return values.size(); }
  /// Appends the entry value * u_component(node) to the row under construction.
  void add_entry(int node, int component, double value);
  /// Closes the row under construction with weight m_j.
  void finish_row(double weight);
};

/// Entry by entry equality (the same rows, nodes, components, coefficients and weights).
bool operator==(const ContactOperator& left, const ContactOperator& right);
inline bool operator!=(const ContactOperator& left, const ContactOperator& right) {
  return !(left == right);
}

/// One row per node: (B u)_i = u(nodes[i]) . normals[i], weight weights[i].
ContactOperator node_to_node_operator(const std::vector<int>& nodes,
                                      const std::vector<Eigen::Vector3d>& normals,
                                      const std::vector<double>& weights);

/// Checks the structure of `contact` against the body's contact nodes (sorted ascending):
/// offsets start at 0, do not decrease and end at the entry count; no empty row; every node a
/// contact node; components 0 .. dimension - 1; finite values; distinct (node, component) pairs in
/// a row; one finite weight m_j > 0 per row. Throws InputError "<context>: <field> ..." naming the
/// first problem (the field names are those of the protocol's AssignContact).
void check_contact_operator(const ContactOperator& contact, const std::vector<int>& contact_nodes,
                            int dimension, const std::string& context);

}  // namespace robin
