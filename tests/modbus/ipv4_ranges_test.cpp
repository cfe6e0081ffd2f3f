// The address lists of `plc_address` and `allow`: single addresses and CIDR blocks, and
// the errors a wrong entry gets.
#include "ipv4_ranges.h"

#include <arpa/inet.h>

#include <gtest/gtest.h>

#include "tilth/error.h"

namespace tilth::modbus {
namespace {

std::uint32_t ip(const char* text) {
  in_addr address{};
  EXPECT_EQ(inet_pton(AF_INET, text, &address), 1) << text;
  return ntohl(address.s_addr);
}

std::string parse_error(const nlohmann::json& value) {
  try {
    Ipv4Ranges::parse("allow", value);
  } catch (const Error& error) {
    return error.what();
  }
  return "no error";
}

TEST(Ipv4Ranges, OneAddressIsThatAddressOnly) {
  const Ipv4Ranges plc = Ipv4Ranges::parse("plc_address", "192.168.1.10");
  EXPECT_TRUE(plc.contains(ip("192.168.1.10")));
  EXPECT_FALSE(plc.contains(ip("192.168.1.11")));
  EXPECT_FALSE(plc.contains(ip("192.168.1.9")));
  EXPECT_EQ(plc.text(), "192.168.1.10");
}

TEST(Ipv4Ranges, CidrBlocksAndLists) {
  const Ipv4Ranges allow = Ipv4Ranges::parse(
      "allow", nlohmann::json::array({"10.0.0.0/8", "192.168.1.16/28", "172.16.0.1/32"}));
  EXPECT_TRUE(allow.contains(ip("10.255.255.255")));
  EXPECT_FALSE(allow.contains(ip("11.0.0.0")));
  EXPECT_FALSE(allow.contains(ip("192.168.1.15")));
  EXPECT_TRUE(allow.contains(ip("192.168.1.16")));
  EXPECT_TRUE(allow.contains(ip("192.168.1.31")));
  EXPECT_FALSE(allow.contains(ip("192.168.1.32")));
  EXPECT_TRUE(allow.contains(ip("172.16.0.1")));
  EXPECT_FALSE(allow.contains(ip("172.16.0.2")));
  EXPECT_EQ(allow.text(), "10.0.0.0/8, 192.168.1.16/28, 172.16.0.1");
}

TEST(Ipv4Ranges, EmptyListAndEverything) {
  EXPECT_TRUE(Ipv4Ranges::parse("allow", nlohmann::json::array()).empty());
  const Ipv4Ranges everything = Ipv4Ranges::parse("allow", "0.0.0.0/0");
  EXPECT_TRUE(everything.contains(ip("0.0.0.0")));
  EXPECT_TRUE(everything.contains(ip("255.255.255.255")));
}

TEST(Ipv4Ranges, WrongEntriesNameTheParameterEntryAndExpectation) {
  const std::string expected =
      "expected an IPv4 address such as 192.168.1.10 or a CIDR block such as 192.168.1.0/24";
  EXPECT_EQ(parse_error("plc"), "parameter 'allow': " + expected + ", got 'plc'");
  EXPECT_EQ(parse_error(nlohmann::json::array({"10.0.0.1", "10.0.0.256"})),
            "parameter 'allow'/1: " + expected + ", got '10.0.0.256'");
  EXPECT_EQ(parse_error(nlohmann::json::array({"10.0.0.1", 7})),
            "parameter 'allow'/1: " + expected + ", got 7");
  EXPECT_EQ(parse_error("10.0.0.0/33"),
            "parameter 'allow': " + expected + " (prefix length 0..32), got '10.0.0.0/33'");
  EXPECT_EQ(parse_error("10.0.0.0/"),
            "parameter 'allow': " + expected + " (prefix length 0..32), got '10.0.0.0/'");
  EXPECT_EQ(parse_error("10.0.0.0/8x"),
            "parameter 'allow': " + expected + " (prefix length 0..32), got '10.0.0.0/8x'");
  EXPECT_EQ(parse_error("192.168.1.10/24"),
            "parameter 'allow': '192.168.1.10/24' has host bits set (expected 192.168.1.0/24)");
  EXPECT_EQ(parse_error(nullptr), "parameter 'allow': " + expected + ", got null");
}

}  // namespace
}  // namespace tilth::modbus
