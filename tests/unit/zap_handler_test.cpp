// The ZAP handler's verdicts (RFC 27, ZAP 1.0) on requests built here frame by frame: an
// allowed CURVE key gets 200, an unknown key, another mechanism or a missing key 400, a request
// that is not ZAP 1.0 gets 500; the reply echoes the version and the request id. The transport
// side (a refused coordinator, the server going on) is tested with real processes in
// tests/integration/curve_transport_test.cpp.

#include "server/zap_handler.hpp"

#include <gtest/gtest.h>
#include <zmq.h>

#include <array>

#include "curve_keys.hpp"

namespace robin {
namespace {

/// The 32 bytes of a Z85 key, decoded by libzmq.
std::string binary_key(const std::string& z85) {
  std::array<std::uint8_t, 32> bytes{};
  EXPECT_NE(zmq_z85_decode(bytes.data(), z85.c_str()), nullptr);
  return std::string(bytes.begin(), bytes.end());
}

std::vector<std::string> curve_request(const std::string& client_key) {
  return {"1.0", "17", "", "10.0.0.7", "", "CURVE", binary_key(client_key)};
}

TEST(ZapHandler, AdmitsExactlyTheKeysOfTheAllowList) {
  const std::string allowed = generate_curve_key_pair().public_key;
  const std::string stranger = generate_curve_key_pair().public_key;
  const std::set<std::string> allow_list{allowed};

  const ZapDecision admitted = decide_zap_request(curve_request(allowed), allow_list);
  EXPECT_EQ(admitted.status_code, "200");
  EXPECT_EQ(admitted.client_key, allowed);
  EXPECT_EQ(admitted.address, "10.0.0.7");

  const ZapDecision refused = decide_zap_request(curve_request(stranger), allow_list);
  EXPECT_EQ(refused.status_code, "400");
  EXPECT_EQ(refused.client_key, stranger);
  EXPECT_NE(refused.status_text.find("not on the allow-list"), std::string::npos);

  const std::vector<std::string> reply = zap_reply(curve_request(stranger), refused);
  EXPECT_EQ(reply,
            (std::vector<std::string>{"1.0", "17", "400", refused.status_text, stranger, ""}));
}

TEST(ZapHandler, RefusesOtherMechanismsAndMalformedRequests) {
  const std::string allowed = generate_curve_key_pair().public_key;
  const std::set<std::string> allow_list{allowed};
  EXPECT_EQ(decide_zap_request({"1.0", "1", "", "127.0.0.1", "", "NULL"}, allow_list).status_code,
            "400");
  EXPECT_EQ(
      decide_zap_request({"1.0", "1", "", "127.0.0.1", "", "PLAIN", "user", "password"}, allow_list)
          .status_code,
      "400");
  EXPECT_EQ(decide_zap_request({"1.0", "1", "", "127.0.0.1", "", "CURVE", "short"}, allow_list)
                .status_code,
            "400");
  std::vector<std::string> other_version = curve_request(allowed);
  other_version[0] = "2.0";
  EXPECT_EQ(decide_zap_request(other_version, allow_list).status_code, "500");
  EXPECT_EQ(decide_zap_request({"1.0", "1"}, allow_list).status_code, "500");
  EXPECT_EQ(zap_reply({}, decide_zap_request({}, allow_list)).size(), 6u);
}

}  // namespace
}  // namespace robin
