#pragma once
// The contact graph of a run: bodies 0..N-1 and interfaces k = 0..M-1, interface k joining
// bodies a(k) != b(k) with r_k constraint rows B^a_k u^a + B^b_k u^b <= d_k (node pairs or
// mortar rows, contact_pairing.hpp). Two bodies with one interface is the graph of one edge.
//
// Two orders of the constraint rows:
//  - global order: interface 0's rows, then interface 1's, ... (gaps d, weights m, the
//    monolithic contact force);
//  - body order, per body alpha: the rows of alpha's interfaces in interface order. Body alpha's
//    constraint operator B^alpha stacks its B^alpha_k in this order, and every per-body vector
//    of the iteration (obstacle g^alpha, trace u^alpha_N, force lambda^alpha, correction
//    w^alpha_N) is in it.
// For one interface both orders coincide with the pair order of contact_pairing.hpp.
//
// Every row has two sides, a(k) and b(k). The Robin iteration on a graph (docs/method.md):
// body alpha solves its contact problem against its obstacle on all its rows at once; its
// correction solve is driven on each row by lambda^other - lambda^alpha; the obstacle of each
// side of a row is updated from the other side of the same row.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "numerics/contact_operator.hpp"

namespace robin {

/// One edge of the contact graph.
struct GraphInterface {
  int body_a = 0;
  int body_b = 1;
  Eigen::Index rows = 0;
  Eigen::Index global_offset = 0;  // first row in global order
  Eigen::Index offset_a = 0;       // first row in body a's order
  Eigen::Index offset_b = 0;       // first row in body b's order
};

class ContactGraph {
 public:
  /// One row per (body_a, body_b, rows) triple, in interface order. Throws InputError when a
  /// body index is out of range, an interface joins a body to itself or there are no bodies.
  struct Edge {
    int body_a = 0;
    int body_b = 1;
    Eigen::Index rows = 0;
  };
  ContactGraph(int body_count, const std::vector<Edge>& edges);
  /// Two bodies and one interface of `rows` rows (body order = pair order).
  static ContactGraph two_bodies(Eigen::Index rows);

  int body_count() const { return body_count_; }
  const std::vector<GraphInterface>& interfaces() const { return interfaces_; }
  Eigen::Index total_rows() const { return total_rows_; }
  /// The number of rows in body `body`'s order (0 for a body without interfaces).
  Eigen::Index body_rows(int body) const { return body_rows_[static_cast<std::size_t>(body)]; }

  /// Body `body`'s rows of a vector in global order.
  Eigen::VectorXd body_part(int body, const Eigen::VectorXd& global) const;
  /// Adds body `body`'s rows `part` (body order) onto `global` (global order): the transpose
  /// of body_part.
  void add_body_part(int body, const Eigen::VectorXd& part, Eigen::VectorXd& global) const;
  /// On each of body `body`'s rows, the value of the other side of the row in `per_body`
  /// (vectors in body order, one per body).
  Eigen::VectorXd across(int body, const std::vector<Eigen::VectorXd>& per_body) const;
  /// The values of the a sides (side = 0) or b sides (side = 1) of every row, in global order.
  Eigen::VectorXd side(int side, const std::vector<Eigen::VectorXd>& per_body) const;
  /// The body whose side `side` (0: a, 1: b) holds global row `row`.
  int body_of_row(Eigen::Index row, int side) const;

  /// A 2-colouring of the bodies (colour 0 or 1; neighbours differ; the lowest body of each
  /// connected component, and every body without interfaces, get colour 0), or nothing when
  /// the graph has an odd cycle.
  std::optional<std::vector<int>> two_colouring() const;
  /// The connected component of every body (0, 1, ... in the order of their lowest body).
  std::vector<int> components() const;

 private:
  int body_count_ = 0;
  std::vector<GraphInterface> interfaces_;
  std::vector<Eigen::Index> body_rows_;
  Eigen::Index total_rows_ = 0;
};

/// The rows of `parts` stacked in order into one operator (body alpha's B^alpha from its
/// interfaces' B^alpha_k).
ContactOperator stack_operators(const std::vector<const ContactOperator*>& parts);

/// The vectors one after the other (per-interface or per-body parts into one vector).
Eigen::VectorXd concatenate(const std::vector<Eigen::VectorXd>& parts);

/// "body 1", "bodies 1 and 3", "bodies 1, 3 and 5" for the 0-based `bodies` (for messages).
std::string describe_bodies(const std::vector<int>& bodies);

}  // namespace robin
