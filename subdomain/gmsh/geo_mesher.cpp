#include "gmsh/geo_mesher.hpp"

#include <gmsh.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "numerics/errors.hpp"

namespace robin {

namespace {

/// Gmsh for one script: a fresh initialize/finalize pair, since a script may set options that
/// must not carry over, and `-setnumber h SIZE` defines the .geo variable h before any script is
/// parsed. AbortOnError = 0 keeps Gmsh from throwing out of its parser; errors are collected
/// from Gmsh's logger instead.
class GmshSession {
 public:
  explicit GmshSession(double size) {
    std::vector<std::string> arguments = {"robin"};
    if (size > 0.0) {
      std::ostringstream value;
      value.precision(17);
      value << size;
      arguments.insert(arguments.end(), {"-setnumber", "h", value.str()});
    }
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    gmsh::initialize(static_cast<int>(argv.size()), argv.data(), false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
    gmsh::option::setNumber("General.AbortOnError", 0);
    gmsh::logger::start();
  }
  ~GmshSession() {
    gmsh::logger::stop();
    gmsh::finalize();
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

/// The errors Gmsh logged during this session ("" when none), joined by "; ".
std::string gmsh_errors() {
  std::vector<std::string> log;
  gmsh::logger::get(log);
  const std::string prefix = "Error: ";
  std::string errors;
  for (const std::string& line : log) {
    if (line.rfind(prefix, 0) != 0) continue;
    errors += (errors.empty() ? "" : "; ") + line.substr(prefix.size());
  }
  if (errors.empty()) gmsh::logger::getLastError(errors);
  return errors;
}

/// Runs a Gmsh call; a Gmsh error (thrown or only logged) becomes an InputError "NAME: ACTION
/// failed: ERRORS".
template <typename Call>
void call_gmsh(const std::string& name, const std::string& action, Call&& call) {
  try {
    call();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& exception) {
    throw InputError(name + ": " + action + " failed: " + exception.what());
  } catch (...) {
    const std::string error = gmsh_errors();
    throw InputError(name + ": " + action +
                     " failed: " + (error.empty() ? "unknown Gmsh error" : error));
  }
  const std::string error = gmsh_errors();
  if (!error.empty()) throw InputError(name + ": " + action + " failed: " + error);
}

/// The model's dimension: 3 when it has a volume, 2 otherwise.
int model_dimension() {
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  return volumes.empty() ? 2 : 3;
}

}  // namespace

void mesh_geo_file(const std::filesystem::path& geo, const MeshReadOptions& options,
                   const std::filesystem::path& output) {
  const std::string name = "mesh file '" + geo.string() + "'";
  if (!std::isfinite(options.size) || options.size < 0.0) {
    throw InputError(name + ": mesh size " + std::to_string(options.size) + " is not >= 0");
  }
  if (options.element_order != 1 && options.element_order != 2) {
    throw InputError(name + ": element order " + std::to_string(options.element_order) +
                     " is not 1 or 2");
  }
  const GmshSession session(options.size);
  call_gmsh(name, "reading", [&] { gmsh::open(geo.string()); });
  call_gmsh(name, "meshing", [&] {
    gmsh::option::setNumber("Mesh.ElementOrder", options.element_order);
    if (options.recombine) gmsh::option::setNumber("Mesh.RecombineAll", 1);
    gmsh::model::mesh::generate(model_dimension());
  });
  call_gmsh(name, "writing the mesh", [&] {
    gmsh::option::setNumber("Mesh.Binary", 1);
    gmsh::option::setNumber("Mesh.SaveAll", 1);
    gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
    gmsh::write(output.string());
  });
}

}  // namespace robin
