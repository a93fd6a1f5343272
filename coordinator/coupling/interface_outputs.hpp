#pragma once
// The per-interface result files and summaries of a run on a contact graph (README.md,
// "Results"), shared by robin-monolithic and the coordinator:
//   contact.csv                     a case with one interface (two bodies), as always;
//   contact_<k>_<a>_<b>.csv         a case with several: interface k (1-based) between bodies
//                                   a and b (their names), the columns of contact.csv with
//                                   1 = body a and 2 = body b;
// and summary.json's "interfaces" array: per interface its bodies, boundaries, discretization,
// rows, excluded pairs, contact force resultant and file.

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "coupling/coupling_scheme.hpp"
#include "coupling/graph_coupling.hpp"
#include "coupling/monolithic_solver.hpp"
#include "coupling/result_files.hpp"

namespace robin {

/// What steps.csv, summary.json and the logs say about one interface's state.
struct InterfaceSummary {
  int active_pairs = 0;                                 // rows with a positive mean contact force
  double largest_pressure = 0.0;                        // max_i (lambda1_i + lambda2_i) / (2 m_i)
  Eigen::Vector3d resultant = Eigen::Vector3d::Zero();  // contact_resultant of the mean force
};

InterfaceSummary summarize_interface(const ContactPairing& pairing, const InterfaceState& state);

/// The contact file of interface `interface` among `interface_count`: "contact.csv" for one,
/// "contact_<k>_<a>_<b>.csv" otherwise (k = interface + 1; a, b the names of its bodies).
std::string contact_file_name(const ContactGraph& graph, const std::vector<std::string>& names,
                              std::size_t interface);

/// Whether `state` holds every body's vectors at the sizes of the coupling's rows (a scheme
/// that does not report some body's state, or a state of another coupling, has not).
bool has_interface_state(const GraphCoupling& coupling, const CouplingState& state);

/// Writes every interface's contact file into `directory`; returns their names in interface
/// order. `state` holds every body's vectors in body order.
std::vector<std::string> write_contact_files(const std::filesystem::path& directory,
                                             const GraphCoupling& coupling,
                                             const std::vector<std::string>& names,
                                             const CouplingState& state);

/// The "interfaces" array of summary.json (see the header comment).
nlohmann::json interfaces_json(const GraphCoupling& coupling,
                               const std::vector<InterfaceDefinition>& interfaces,
                               const std::vector<std::string>& names, const CouplingState& state);

/// One line per interface for logs: its discretization (describe_contact) with the bodies'
/// names, numbered when there are several.
std::vector<std::string> describe_interfaces(const GraphCoupling& coupling,
                                             const std::vector<std::string>& names);

/// Every interface's excluded pairs (one line each) and initial-overlap warnings.
std::vector<std::string> excluded_pair_lines(const GraphCoupling& coupling);
std::vector<std::string> overlap_warnings(const GraphCoupling& coupling);

/// The monolithic solution as a coupled state: per body its traces and its part of lambda.
CouplingState monolithic_state(const ContactGraph& graph, const MonolithicResult& result);

/// The clearance of the excluded pairs of every interface (the worst one), with
/// `displacement_of(body, pair, side)` the displacement of body `body`'s node of `pair` on
/// side `side` (0: the interface's body a, 1: body b).
using GraphPairDisplacement =
    std::function<Eigen::Vector3d(int body, const ContactPair& pair, int side)>;
ExcludedPairClearance graph_excluded_clearance(const GraphCoupling& coupling,
                                               const CouplingState& state,
                                               const GraphPairDisplacement& displacement_of);

}  // namespace robin
