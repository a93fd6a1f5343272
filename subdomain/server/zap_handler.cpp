#include "server/zap_handler.hpp"

#include <zmq.h>

#include <array>
#include <cerrno>

#include "server/server_logging.hpp"

namespace robin {

namespace {

const char* const zap_address = "inproc://zeromq.zap.01";
const std::string zap_version = "1.0";
constexpr auto poll_interval = std::chrono::milliseconds(100);

enum Frame : std::size_t {
  version = 0,
  request_id,
  domain,
  address,
  identity,
  mechanism,
  credentials
};

std::string z85(const std::string& key) {
  std::array<char, 41> text{};
  if (key.size() != 32 ||
      zmq_z85_encode(text.data(), reinterpret_cast<const std::uint8_t*>(key.data()), 32) ==
          nullptr) {
    return "";
  }
  return text.data();
}

}  // namespace

ZapDecision decide_zap_request(const std::vector<std::string>& request,
                               const std::set<std::string>& allowed) {
  if (request.size() <= Frame::mechanism || request[Frame::version] != zap_version) {
    return {"500", "not a ZAP 1.0 request", "", ""};
  }
  ZapDecision decision{"400", "", "", request[Frame::address]};
  if (request[Frame::mechanism] != "CURVE") {
    decision.status_text = "only CURVE clients are admitted, not " + request[Frame::mechanism];
    return decision;
  }
  if (request.size() <= Frame::credentials || request[Frame::credentials].size() != 32) {
    decision.status_text = "no CURVE public key in the request";
    return decision;
  }
  decision.client_key = z85(request[Frame::credentials]);
  if (allowed.count(decision.client_key) == 0) {
    decision.status_text = "the client's public key is not on the allow-list";
    return decision;
  }
  decision.status_code = "200";
  decision.status_text = "OK";
  return decision;
}

std::vector<std::string> zap_reply(const std::vector<std::string>& request,
                                   const ZapDecision& decision) {
  const std::string id = request.size() > Frame::request_id ? request[Frame::request_id] : "";
  return {zap_version, id, decision.status_code, decision.status_text, decision.client_key, ""};
}

ZapHandler::ZapHandler(zmq::context_t& context, const std::vector<std::string>& allowed_keys,
                       std::string allow_list)
    : socket_(context, zmq::socket_type::rep),
      allowed_(allowed_keys.begin(), allowed_keys.end()),
      allow_list_(std::move(allow_list)) {
  socket_.set(zmq::sockopt::linger, 0);
  socket_.bind(zap_address);  // before the thread starts: bound when the constructor returns
  thread_ = std::thread([this] { serve(); });
}

ZapHandler::~ZapHandler() {
  stop_.store(true);
  thread_.join();
}

void ZapHandler::serve() {
  const auto logger = subdomain_logger();
  while (!stop_.load()) {
    try {
      zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, poll_interval);
      if ((item.revents & ZMQ_POLLIN) == 0) continue;
      std::vector<std::string> request;
      zmq::message_t frame;
      do {
        if (!socket_.recv(frame, zmq::recv_flags::none)) break;
        request.push_back(frame.to_string());
      } while (frame.more());
      answer(request);
    } catch (const zmq::error_t& error) {
      if (error.num() == EINTR) continue;
      if (error.num() == ETERM) return;
      logger->error("authentication handler: {}", error.what());
    }
  }
}

void ZapHandler::answer(const std::vector<std::string>& request) {
  const ZapDecision decision = decide_zap_request(request, allowed_);
  const auto logger = subdomain_logger();
  if (decision.status_code == "200") {
    logger->info("admitted a client from {} (CURVE public key {})", decision.address,
                 decision.client_key);
  } else if (decision.client_key.empty()) {
    logger->warn("refused a client from {}: {}", decision.address, decision.status_text);
  } else {
    logger->warn("refused a client from {}: its CURVE public key {} is not on the allow-list {}",
                 decision.address, decision.client_key, allow_list_);
  }
  const std::vector<std::string> reply = zap_reply(request, decision);
  for (std::size_t index = 0; index < reply.size(); ++index) {
    const auto flags = index + 1 < reply.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
    socket_.send(zmq::buffer(reply[index]), flags);
  }
}

}  // namespace robin
