// The contact graph's row bookkeeping (coupling/contact_graph.hpp) on small graphs whose body
// orders are written out by hand: a chain 0 - 1 - 2 (the middle body has the rows of both
// interfaces), two bodies (body order = pair order), and a triangle (an odd cycle: no
// 2-colouring).

#include <gtest/gtest.h>

#include "coupling/contact_graph.hpp"
#include "numerics/errors.hpp"

namespace robin {
namespace {

Eigen::VectorXd vector(std::initializer_list<double> values) {
  Eigen::VectorXd result(static_cast<Eigen::Index>(values.size()));
  Eigen::Index index = 0;
  for (const double value : values) result[index++] = value;
  return result;
}

/// Bodies 0 - 1 - 2: interface 0 (bodies 0, 1) has 2 rows, interface 1 (bodies 2, 1) has 3 rows,
/// so body 1 is side b of both: its order is interface 0's rows, then interface 1's.
ContactGraph chain() {
  return ContactGraph(3, {{0, 1, 2}, {2, 1, 3}});
}

TEST(ContactGraph, ChainOffsetsAndBodyParts) {
  const ContactGraph graph = chain();
  EXPECT_EQ(graph.total_rows(), 5);
  EXPECT_EQ(graph.body_rows(0), 2);
  EXPECT_EQ(graph.body_rows(1), 5);
  EXPECT_EQ(graph.body_rows(2), 3);
  const Eigen::VectorXd global = vector({10, 11, 20, 21, 22});
  EXPECT_EQ(graph.body_part(0, global), vector({10, 11}));
  EXPECT_EQ(graph.body_part(1, global), vector({10, 11, 20, 21, 22}));
  EXPECT_EQ(graph.body_part(2, global), vector({20, 21, 22}));
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(5);
  graph.add_body_part(0, vector({1, 2}), sum);
  graph.add_body_part(1, vector({10, 20, 30, 40, 50}), sum);
  graph.add_body_part(2, vector({100, 200, 300}), sum);
  EXPECT_EQ(sum, vector({11, 22, 130, 240, 350}));
}

TEST(ContactGraph, AcrossGivesTheOtherSideOfEveryRow) {
  const ContactGraph graph = chain();
  const std::vector<Eigen::VectorXd> per_body = {vector({1, 2}), vector({3, 4, 5, 6, 7}),
                                                 vector({8, 9, 10})};
  EXPECT_EQ(graph.across(0, per_body), vector({3, 4}));
  EXPECT_EQ(graph.across(1, per_body), vector({1, 2, 8, 9, 10}));
  EXPECT_EQ(graph.across(2, per_body), vector({5, 6, 7}));
  EXPECT_EQ(graph.side(0, per_body), vector({1, 2, 8, 9, 10}));  // a sides: bodies 0 and 2
  EXPECT_EQ(graph.side(1, per_body), vector({3, 4, 5, 6, 7}));   // b sides: body 1 twice
  EXPECT_EQ(graph.body_of_row(3, 0), 2);
  EXPECT_EQ(graph.body_of_row(3, 1), 1);
}

TEST(ContactGraph, TwoBodiesKeepThePairOrder) {
  const ContactGraph graph = ContactGraph::two_bodies(3);
  const Eigen::VectorXd values = vector({1, 2, 3});
  EXPECT_EQ(graph.body_part(0, values), values);
  EXPECT_EQ(graph.body_part(1, values), values);
  EXPECT_EQ(graph.across(0, {values, 2 * values}), 2 * values);
  EXPECT_EQ(graph.across(1, {values, 2 * values}), values);
  EXPECT_EQ(graph.two_colouring(), (std::vector<int>{0, 1}));
}

TEST(ContactGraph, ColouringOfAChainAndNoneForATriangle) {
  EXPECT_EQ(chain().two_colouring(), (std::vector<int>{0, 1, 0}));
  const ContactGraph triangle(3, {{0, 1, 1}, {1, 2, 1}, {2, 0, 1}});
  EXPECT_FALSE(triangle.two_colouring().has_value());
  const ContactGraph ring(4, {{0, 1, 1}, {1, 2, 1}, {2, 3, 1}, {3, 0, 1}});
  EXPECT_EQ(ring.two_colouring(), (std::vector<int>{0, 1, 0, 1}));
}

TEST(ContactGraph, RefusesSelfContactAndUnknownBodies) {
  EXPECT_THROW(ContactGraph(2, {{0, 0, 1}}), InputError);
  EXPECT_THROW(ContactGraph(2, {{0, 2, 1}}), InputError);
  EXPECT_THROW(ContactGraph(0, {}), InputError);
}

TEST(ContactGraph, StackedOperatorKeepsRowsInOrder) {
  ContactOperator first;
  first.add_entry(3, 1, 1.0);
  first.finish_row(0.5);
  ContactOperator second;
  second.add_entry(7, 0, -1.0);
  second.add_entry(8, 1, 0.25);
  second.finish_row(2.0);
  const ContactOperator stacked = stack_operators({&first, &second});
  EXPECT_EQ(stacked.row_count(), 2);
  EXPECT_EQ(stacked.row_offsets, (std::vector<std::size_t>{0, 1, 3}));
  EXPECT_EQ(stacked.nodes, (std::vector<int>{3, 7, 8}));
  EXPECT_EQ(stacked.components, (std::vector<int>{1, 0, 1}));
  EXPECT_EQ(stacked.values, (std::vector<double>{1.0, -1.0, 0.25}));
  EXPECT_EQ(stacked.weights, (std::vector<double>{0.5, 2.0}));
  EXPECT_EQ(describe_bodies({0}), "body 1");
  EXPECT_EQ(describe_bodies({0, 2}), "bodies 1 and 3");
  EXPECT_EQ(describe_bodies({0, 2, 4}), "bodies 1, 3 and 5");
}

}  // namespace
}  // namespace robin
