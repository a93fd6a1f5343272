#pragma once
// The conformance checker's built-in body, the requests about it and the judgement of the
// replies (internal to robin_remote; see conformance_check.hpp).
//
// The body: the unit square [0, 1]^2 (sent as MeshData: a structured mesh of 4 x 4 squares,
// each split into two linear triangles), isotropic plane strain (E = 1000, nu = 0.3), its bottom
// edge prescribed to u = (0, lift), no load, its top edge y = 1 the contact boundary with outward
// normal (0, 1). Without contact it translates rigidly: u = (0, lift) everywhere, no stress, so the
// free normal trace is e_i = lift at every contact node. On this mesh F = B K^-1 B' is such that a
// unit force at a node moves that node most (the largest entry of each column is on the diagonal;
// both shipped servers pass the check that relies on it).
//
// Every judging function returns plain-words problems ("" or an empty list when the reply is
// right), naming the field and the node.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "remote/conformance_session.hpp"
#include "robin.pb.h"

namespace robin::conformance {

inline constexpr const char* body_name = "conformance_square";
inline constexpr double young_modulus = 1000.0;
inline constexpr double lift = 0.01;  // prescribed u_y of the bottom edge, = e_i on the top
inline constexpr double contact_length = 1.0;
inline constexpr double far_obstacle = 1.0;  // g_i >> lift: no contact
/// A reference force: the whole top edge pushed back by `lift` (E * strain * length).
inline constexpr double force_reference = young_modulus * lift * contact_length;

/// The partial-contact obstacle of a node at abscissa x: below the free trace `lift` for
/// x < 0.5, above it for x > 0.5, so that some nodes touch and others do not.
double partial_obstacle(double x);

/// The valid SetupBody of the built-in body (tests derive the refused ones from it).
protocol::SetupBody square_body();
/// `body` with its isotropic young_modulus/poisson_ratio replaced by the equivalent row-major
/// 3x3 `voigt` matrix of its model (Voigt order xx, yy, xy, engineering shear strain), as
/// robin-coordinator sends every material that is not isotropic plane strain:
///   plane strain: E / ((1 + nu)(1 - 2 nu)) [[1 - nu, nu, 0], [nu, 1 - nu, 0],
///                                           [0, 0, (1 - 2 nu) / 2]],
///   plane stress: E / (1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]].
/// Both definitions describe the same material: a server must give the same answers.
protocol::SetupBody with_voigt_material(protocol::SetupBody body);

/// A contact node of the built-in body: its server-side id and abscissa.
struct ContactNode {
  std::int64_t id = 0;
  double x = 0.0;
};

protocol::Envelope setup_request(const protocol::SetupBody& body);
/// AssignContact of one node-to-node row per node of `nodes`, in that (constraint) order, each
/// with the normal (0, normal_length) and weight 1.
protocol::Envelope assign_request(const std::vector<ContactNode>& nodes,
                                  double normal_length = 1.0);
protocol::Envelope contact_solve_request(const Eigen::VectorXd& obstacle, unsigned iteration = 1);
protocol::Envelope correction_request(const Eigen::VectorXd& force);
/// NeumannSolveRequest (protocol 1.1) with the contact force lambda.
protocol::Envelope neumann_solve_request(const Eigen::VectorXd& force);
protocol::Envelope fields_request(const Eigen::VectorXd& force);
protocol::Envelope end_run_request();

/// The contact nodes in the pair order the checker assigns: by descending x, or ascending
/// when that is the server's own order (so that a server that ignores the pair order shows).
std::vector<ContactNode> pair_order(const protocol::InterfaceDescription& description);

/// The InterfaceDescription's array sizes, at least two nodes, finite values.
std::string interface_size_problems(const protocol::InterfaceDescription& description);
/// Distinct ids in [0, 2^31), nodes on the top edge, normals (0, 1), positive weights, no
/// fixed flags (no Dirichlet condition reaches the top edge). Sizes must be right.
std::vector<std::string> interface_node_problems(const protocol::InterfaceDescription& description,
                                                 double tolerance);
/// Linear edges: m_i is half the adjacent contact edges' length, the nodes span [0, 1] and the
/// weights sum to the contact boundary's length 1.
std::vector<std::string> interface_weight_problems(
    const protocol::InterfaceDescription& description, double tolerance);

/// The surfaces of the top edge: exactly one ContactSurface, boundary "top", segment_type LINE2
/// or LINE3, `segments` a multiple of its nodes per segment, every position < the node count;
/// each segment of positive length with all its nodes on the top edge (a LINE3 midpoint halfway
/// between its ends); each oriented with the body on its left, i.e. its outward normal, the
/// direction t = x(second) - x(first) turned clockwise, (t_y, -t_x) / |t|, agreeing with the
/// reported normals of its end nodes (dot product > 1 - tolerance); the segments' lengths
/// summing to the edge's length 1 and every node in some segment. Sizes must be right.
std::vector<std::string> interface_surface_problems(
    const protocol::InterfaceDescription& description, double tolerance);

struct ContactSolution {
  Eigen::VectorXd normal_trace;   // u_N
  Eigen::VectorXd contact_force;  // lambda
};

/// A ContactSolveResult: CONVERGED, `count` finite values (active: `count` or none).
std::string read_contact_solution(const Exchange& exchange, long count, ContactSolution& solution);
/// lambda_i >= 0, u_N,i <= g_i and lambda_i (g_i - u_N,i) = 0, relative to the solution's
/// force scale max |lambda| and length scale max(max |g|, lift).
std::vector<std::string> signorini_problems(const ContactSolution& solution,
                                            const Eigen::VectorXd& obstacle, double tolerance);
/// A CorrectionResult of `count` finite values.
std::string read_correction(const Exchange& exchange, long count, Eigen::VectorXd& trace);

/// A NeumannSolveResult of `count` finite values.
std::string read_neumann_solution(const Exchange& exchange, long count, Eigen::VectorXd& trace);

/// The FieldsReply's mesh: (x, y) per node, node_tags for every node or none, cell blocks of
/// VTK types 5, 22, 9 with consistent offsets and indices, field sizes, 2 or no values in
/// reaction_resultant and applied_force.
std::vector<std::string> fields_structure_problems(const protocol::FieldsReply& fields);
/// (x, y) of a repeated field of 2 values; zero when empty.
Eigen::Vector2d resultant(const google::protobuf::RepeatedField<double>& values);
/// The abscissa of the top-edge node (y = 1) that the FieldsReply's displacement moves down
/// most; a problem when there is no top-edge node. Throws NotChecked without a usable
/// 'displacement' point field.
std::string most_pushed_top_node(const protocol::FieldsReply& fields, double tolerance,
                                 double& abscissa);

}  // namespace robin::conformance
