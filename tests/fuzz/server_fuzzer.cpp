// libFuzzer harness: the subdomain server's request decoding and dispatch. Every input is a
// request as it would arrive from the wire (the bytes of a serialized robin.protocol.Envelope,
// or anything else) and goes to SubdomainServer::handle of ONE long-lived server, so that state
// carries over from input to input: a SetupBody leaves a body that later AssignContact, solves,
// fields and EndRun act on.
//
// An input may also hold a short session: requests separated by the marker `request_separator`
// below (at most `maximum_requests`), handed to handle() one after the other. An input without
// the marker is one request. The session seeds (corpus/server/session_*.pb: SetupBody,
// AssignContact, solves, fields) let mutations of the later requests meet a body that was just
// set up and assigned, instead of whatever state the previous inputs left (most mutated
// SetupBody requests fail, and a failed SetupBody discards the body).
//
// Reproducing a crash that needs earlier requests: pass them first, e.g.
// robin-fuzz-server corpus/server/setup_body_triangle3.pb corpus/server/assign_contact.pb
// crash-... (libFuzzer runs files given on the command line in order, in one process).
//
// The server is confined and bounded: its data directory (SetupBody.mesh_path) and output root
// (FieldsRequest.write_directory) are fresh temporary directories created once (the data
// directory holds one small Gmsh mesh, square.msh), and its limits (maximum_dofs,
// maximum_factor_bytes) keep a fuzzed body from making the fuzzer slow or exhausting memory.
//
// Besides "no crash, leak, undefined behaviour or timeout", every reply is checked: it must
// parse as an Envelope carrying the server's version and echoing the request_id of a parsable
// request, and an Error reply must name the server's actual state.

#include <google/protobuf/stubs/logging.h>
#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>
#include <string.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "robin.pb.h"
#include "server/subdomain_server.hpp"

namespace {

namespace fs = std::filesystem;

/// Separates the requests of a session input (robin-fuzz-make-corpus writes the same marker).
constexpr std::string_view request_separator = "<robin-fuzz-next-request>";
constexpr int maximum_requests = 8;

/// The temporary directories of the server, removed when the fuzzer exits normally.
struct FuzzDirectories {
  fs::path root;
  fs::path data;
  fs::path output;

  FuzzDirectories() {
    std::string pattern = (fs::temp_directory_path() / "robin-fuzz-server-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("robin-fuzz-server: mkdtemp");
      std::abort();
    }
    root = pattern;
    data = root / "data";
    output = root / "output";
    fs::create_directories(data);
    fs::create_directories(output);
    fs::copy_file(ROBIN_FUZZ_MESH_FILE, data / "square.msh");
  }
  ~FuzzDirectories() {
    std::error_code ignored;
    fs::remove_all(root, ignored);
  }
};

robin::SubdomainServer& fuzzed_server() {
  static FuzzDirectories directories;
  static robin::SubdomainServer server([] {
    robin::ServerSettings settings;
    settings.name = "fuzz";
    settings.data_directory = directories.data;
    settings.mesh_reader = ROBIN_MESH_READER;
    settings.output_root = directories.output;
    settings.maximum_dofs = 20000;
    settings.maximum_factor_bytes = 64.0 * 1024 * 1024;
    settings.logger =
        std::make_shared<spdlog::logger>("fuzz", std::make_shared<spdlog::sinks::null_sink_mt>());
    return settings;
  }());
  return server;
}

[[noreturn]] void fail(const char* problem) {
  std::fprintf(stderr, "robin-fuzz-server: %s\n", problem);
  std::abort();
}

/// Sends one request and checks the reply.
void exchange(robin::SubdomainServer& server, std::string_view request) {
  const std::string reply_bytes = server.handle(request);

  robin::protocol::Envelope reply;
  if (!reply.ParseFromString(reply_bytes)) fail("the reply is not a serialized Envelope");
  if (!reply.has_version() || reply.version().major() != robin::protocol::protocol_major) {
    fail("the reply does not carry the server's protocol version");
  }
  robin::protocol::Envelope parsed;
  if (parsed.ParseFromArray(request.data(), static_cast<int>(request.size())) &&
      reply.request_id() != parsed.request_id()) {
    fail("the reply does not echo the request_id");
  }
  if (reply.has_error() && reply.error().state() != robin::to_string(server.state())) {
    fail("the Error reply names another state than the server's");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // Protobuf logs every string field with invalid UTF-8 it refuses to parse; the server answers
  // those with MALFORMED_MESSAGE, and the log lines would only bury libFuzzer's output.
  google::protobuf::SetLogHandler(nullptr);
  fuzzed_server();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  robin::SubdomainServer& server = fuzzed_server();
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  for (int count = 1;; ++count) {
    const void* found = nullptr;
    if (count < maximum_requests && rest.size() >= request_separator.size()) {
      // memmem: libFuzzer's hook on it learns the marker.
      found = memmem(rest.data(), rest.size(), request_separator.data(), request_separator.size());
    }
    if (found == nullptr) {
      exchange(server, rest);
      return 0;
    }
    const auto length = static_cast<std::size_t>(static_cast<const char*>(found) - rest.data());
    exchange(server, rest.substr(0, length));
    rest.remove_prefix(length + request_separator.size());
  }
}
