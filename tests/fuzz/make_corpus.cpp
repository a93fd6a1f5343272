// Writes the seed corpora of the fuzz harnesses (docs/fuzzing.md):
//   robin-fuzz-make-corpus OUTPUT_DIRECTORY      (usually tests/fuzz/corpus)
// writes
//   OUTPUT/server/*.pb     one serialized Envelope per request type (Hello, SetupBody of small
//                          meshes as MeshData and by mesh_path, AssignContact with node-to-node
//                          rows, ContactSolveRequest, CorrectionRequest, NeumannSolveRequest,
//                          FieldsRequest, EndRun, Shutdown), and session_*.pb, the requests of a
//                          run on one body (SetupBody to FieldsRequest) in one input, separated
//                          by the server harness's marker; every request is checked against a
//                          real server: the runs in order get no Error reply;
//   OUTPUT/mesh_data/*.pb  MeshData of small rectangles (triangle3, triangle6, quadrilateral4);
//   OUTPUT/case_file/      copies of examples/*.toml and tests/data/*.toml.
// The three directories are emptied first. The Protobuf output is deterministic for a given
// build (the AssignContact rows use the node ids, normals and weights the server reports).

#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh_codec.hpp"
#include "numerics/rectangle_mesher.hpp"
#include "robin.pb.h"
#include "server/subdomain_server.hpp"

namespace {

namespace fs = std::filesystem;
using robin::protocol::Envelope;

/// Separates the requests of a session input (tests/fuzz/server_fuzzer.cpp splits on it).
const std::string request_separator = "<robin-fuzz-next-request>";

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!file) throw std::runtime_error("cannot write " + path.string());
  std::cout << path.string() << " (" << bytes.size() << " bytes)\n";
}

/// A small rectangle [0, 2] x [-1, 0] with 4 x 2 cells (the contact boundary is "top").
robin::Mesh rectangle(robin::ElementType type, int nx = 4, int ny = 2) {
  robin::Mesh mesh = robin::make_rectangle_mesh(0.0, -1.0, 2.0, 0.0, nx, ny, type);
  mesh.source = "rectangle_" + robin::to_string(type);
  return mesh;
}

Envelope request(std::uint64_t id) {
  Envelope envelope;
  envelope.mutable_version()->set_major(robin::protocol::protocol_major);
  envelope.mutable_version()->set_minor(robin::protocol::protocol_minor);
  envelope.set_request_id(id);
  return envelope;
}

/// Plane strain, E = 1000, nu = 0.3, bottom clamped, contact on "top".
robin::protocol::SetupBody isotropic_setup(robin::ElementType type) {
  robin::protocol::SetupBody setup;
  setup.set_body_name("lower");
  *setup.mutable_mesh() = robin::encode_mesh(rectangle(type));
  setup.set_model(robin::protocol::PLANE_STRAIN);
  setup.set_young_modulus(1000.0);
  setup.set_poisson_ratio(0.3);
  robin::protocol::Dirichlet& bottom = *setup.add_dirichlet();
  bottom.set_boundary("bottom");
  bottom.set_x(0.0);
  bottom.set_y(0.0);
  setup.add_contact_boundaries("top");
  return setup;
}

/// Plane stress with a Voigt matrix, a body force, a traction vector and a pressure, a
/// left support in x only plus the clamped bottom, and explicit solver settings.
robin::protocol::SetupBody voigt_setup() {
  robin::protocol::SetupBody setup;
  setup.set_body_name("upper-2");
  *setup.mutable_mesh() = robin::encode_mesh(rectangle(robin::ElementType::quadrilateral4, 3, 2));
  setup.set_model(robin::protocol::PLANE_STRESS);
  for (const double value : {1100.0, 330.0, 0.0, 330.0, 1100.0, 0.0, 0.0, 0.0, 385.0}) {
    setup.add_voigt(value);
  }
  setup.add_body_force(0.0);
  setup.add_body_force(-1.0);
  robin::protocol::Dirichlet& bottom = *setup.add_dirichlet();
  bottom.set_boundary("bottom");
  bottom.set_x(0.0);
  bottom.set_y(0.001);
  robin::protocol::Dirichlet& left = *setup.add_dirichlet();
  left.set_boundary("left");
  left.set_x(0.0);
  robin::protocol::Traction& right = *setup.add_traction();
  right.set_boundary("right");
  right.add_vector(-0.5);
  right.add_vector(0.25);
  robin::protocol::Traction& pressure = *setup.add_traction();
  pressure.set_boundary("left");
  pressure.set_is_pressure(true);
  pressure.set_pressure(2.0);
  setup.add_contact_boundaries("top");
  robin::protocol::SolverSettings& solver = *setup.mutable_solver();
  solver.set_qp_tolerance(1e-10);
  solver.set_qp_max_iterations(500);
  solver.set_interface_operator("dense");
  solver.set_dense_limit(100);
  solver.set_linear_solver("multigrid");
  return setup;
}

/// The body of tests/data/mesh_square_v41.msh, named by mesh_path (the harness's data
/// directory holds it as square.msh).
robin::protocol::SetupBody mesh_path_setup() {
  robin::protocol::SetupBody setup;
  setup.set_body_name("square");
  setup.set_mesh_path("square.msh");
  setup.set_model(robin::protocol::PLANE_STRAIN);
  setup.set_young_modulus(200.0);
  setup.set_poisson_ratio(0.25);
  robin::protocol::Dirichlet& bottom = *setup.add_dirichlet();
  bottom.set_boundary("bottom");
  bottom.set_x(0.0);
  bottom.set_y(0.0);
  setup.add_contact_boundaries("top");
  setup.mutable_solver()->set_interface_operator("factor");
  setup.mutable_solver()->set_linear_solver("direct");
  return setup;
}

/// Node-to-node rows: one per contact node, (B u)_i = u(node_i) . n_i, weight m_i.
robin::protocol::AssignContact node_to_node(
    const robin::protocol::InterfaceDescription& interface) {
  robin::protocol::AssignContact assign;
  assign.add_row_offsets(0);
  for (int i = 0; i < interface.node_ids_size(); ++i) {
    for (int component = 0; component < 2; ++component) {
      assign.add_node_ids(interface.node_ids(i));
      assign.add_components(static_cast<unsigned>(component));
      assign.add_values(interface.normals(2 * i + component));
    }
    assign.add_row_offsets(static_cast<std::uint64_t>(assign.values_size()));
    assign.add_weights(interface.weights(i));
  }
  return assign;
}

class SeedWriter {
 public:
  SeedWriter(fs::path directory, fs::path scratch) : directory_(std::move(directory)) {
    robin::ServerSettings settings;
    settings.name = "make-corpus";
    settings.data_directory = scratch / "data";
    settings.mesh_reader = ROBIN_MESH_READER;
    settings.output_root = scratch / "output";
    settings.maximum_dofs = 20000;
    settings.maximum_factor_bytes = 64.0 * 1024 * 1024;
    settings.logger = std::make_shared<spdlog::logger>(
        "make-corpus", std::make_shared<spdlog::sinks::null_sink_mt>());
    server_ = std::make_unique<robin::SubdomainServer>(std::move(settings));
  }

  /// Sends `envelope` to the server and returns the reply, which must not be an Error; with
  /// `write`, also writes the envelope as NAME.pb.
  Envelope send(const std::string& name, const Envelope& envelope, bool write = true) {
    const std::string bytes = envelope.SerializeAsString();
    if (write) this->write(name, bytes);
    Envelope reply;
    if (!reply.ParseFromString(server_->handle(bytes))) {
      throw std::runtime_error(name + ": the reply does not parse");
    }
    if (reply.has_error()) {
      throw std::runtime_error(name + ": Error reply: " + reply.error().message());
    }
    return reply;
  }

  void write(const std::string& name, const std::string& bytes) const {
    write_file(directory_ / (name + ".pb"), bytes);
  }

 private:
  fs::path directory_;
  std::unique_ptr<robin::SubdomainServer> server_;
};

/// A run on one body: SetupBody (written as `setup_name`.pb), AssignContact with node-to-node
/// rows, ContactSolveRequest, CorrectionRequest, NeumannSolveRequest and FieldsRequest, sent in
/// order. With `session_seed`, the whole sequence is also written as one session input,
/// session_<suffix>.pb (the requests joined by the harness's separator). With
/// `individual`, every request is also written on its own (assign_contact.pb,
/// contact_solve.pb, ...), and EndRun closes the run.
void write_run(SeedWriter& writer, const std::string& setup_name,
               const robin::protocol::SetupBody& setup, const std::string& run_id, bool individual,
               bool session_seed = true) {
  std::string session;
  const auto send = [&](const std::string& name, Envelope envelope, bool write) {
    envelope.set_run_id(run_id);
    if (!session.empty()) session += request_separator;
    session += envelope.SerializeAsString();
    return writer.send(name, envelope, write);
  };
  Envelope setup_request = request(2);
  *setup_request.mutable_setup_body() = setup;
  const Envelope interface_reply = send(setup_name, setup_request, true);
  const robin::protocol::InterfaceDescription& interface = interface_reply.interface();
  const int rows = interface.node_ids_size();

  Envelope assign = request(3);
  *assign.mutable_assign_contact() = node_to_node(interface);
  send("assign_contact", assign, individual);

  Envelope contact = request(4);
  contact.mutable_contact_solve()->set_iteration(1);
  for (int i = 0; i < rows; ++i) contact.mutable_contact_solve()->add_obstacle(-1e-3);
  const Envelope contact_reply = send("contact_solve", contact, individual);

  Envelope correction = request(5);
  correction.mutable_correction()->set_iteration(1);
  for (int i = 0; i < rows; ++i) correction.mutable_correction()->add_interface_force(0.1);
  send("correction", correction, individual);

  Envelope neumann = request(6);
  neumann.mutable_neumann_solve()->set_iteration(1);
  for (int i = 0; i < rows; ++i) neumann.mutable_neumann_solve()->add_contact_force(0.1);
  send("neumann_solve", neumann, individual);

  Envelope fields = request(7);
  fields.mutable_fields()->mutable_contact_force()->CopyFrom(
      contact_reply.contact_result().contact_force());
  fields.mutable_fields()->set_write_directory("run/out");
  send("fields", fields, individual);

  if (session_seed) {
    writer.write("session_" + setup_name.substr(std::string("setup_body_").size()), session);
  }
  if (!individual) return;
  Envelope end_run = request(8);
  end_run.set_run_id(run_id);
  end_run.mutable_end_run();
  writer.send("end_run", end_run, true);
}

void copy_case_files(const fs::path& directory) {
  const fs::path source(ROBIN_SOURCE_DIR);
  for (const fs::path& folder : {source / "examples", source / "tests/data"}) {
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
      if (entry.path().extension() != ".toml") continue;
      fs::copy_file(entry.path(), directory / entry.path().filename(),
                    fs::copy_options::overwrite_existing);
      std::cout << (directory / entry.path().filename()).string() << '\n';
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: robin-fuzz-make-corpus OUTPUT_DIRECTORY (e.g. tests/fuzz/corpus)\n";
    return 2;
  }
  const fs::path output(argv[1]);
  std::string pattern = (fs::temp_directory_path() / "robin-fuzz-corpus-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    std::perror("mkdtemp");
    return 1;
  }
  const fs::path scratch(pattern);
  try {
    for (const char* harness : {"server", "mesh_data", "case_file"}) {
      fs::remove_all(output / harness);  // all generated: no stale seed stays behind
      fs::create_directories(output / harness);
    }
    fs::create_directories(scratch / "data");
    fs::create_directories(scratch / "output");
    fs::copy_file(fs::path(ROBIN_SOURCE_DIR) / "tests/data/mesh_square_v41.msh",
                  scratch / "data/square.msh");

    // The server's seeds: a whole run in order, against one server.
    SeedWriter writer(output / "server", scratch);
    Envelope hello = request(1);
    hello.mutable_hello()->set_client_name("robin-fuzz-make-corpus");
    hello.mutable_hello()->add_capabilities("fields");
    hello.mutable_hello()->add_capabilities("neumann_solve");
    writer.send("hello", hello);
    write_run(writer, "setup_body_triangle3", isotropic_setup(robin::ElementType::triangle3),
              "0123456789abcdef", true);
    write_run(writer, "setup_body_triangle6", isotropic_setup(robin::ElementType::triangle6), "",
              false);
    write_run(writer, "setup_body_voigt_quadrilateral4", voigt_setup(), "", false);
    // No session seed: every SetupBody by mesh_path starts and stops Gmsh (about 50 ms under
    // ASan), and a session seed of it would make the fuzzer spend most of its time there.
    write_run(writer, "setup_body_mesh_path", mesh_path_setup(), "", false, false);
    Envelope shutdown = request(9);
    shutdown.mutable_shutdown();
    writer.send("shutdown", shutdown);

    // The mesh decoder's seeds.
    for (const auto type : {robin::ElementType::triangle3, robin::ElementType::triangle6,
                            robin::ElementType::quadrilateral4}) {
      write_file(output / "mesh_data" / ("rectangle_" + robin::to_string(type) + ".pb"),
                 robin::encode_mesh(rectangle(type, 2, 1)).SerializeAsString());
    }

    copy_case_files(output / "case_file");
  } catch (const std::exception& error) {
    std::cerr << "robin-fuzz-make-corpus: " << error.what() << '\n';
    fs::remove_all(scratch);
    return 1;
  }
  fs::remove_all(scratch);
  return 0;
}
