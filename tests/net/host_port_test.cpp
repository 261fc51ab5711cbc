// The --connect address of the viewer and fishtank-client: a host and a port that can exist, or a refusal.

#include "common/host_port.h"

#include <catch2/catch.hpp>

using fishtank::parse_host_port;

TEST_CASE("host:port gives the host and a port 1 .. 65535, and an IPv6 literal without its brackets", "[net][flags]") {
  const auto local = parse_host_port("127.0.0.1:7878");
  REQUIRE(local);
  CHECK(local->host == "127.0.0.1");
  CHECK(local->port == 7878);
  CHECK(parse_host_port("tank.example:1")->port == 1);
  CHECK(parse_host_port("tank.example:65535")->port == 65535);
  const auto v6 = parse_host_port("[::1]:7878");
  REQUIRE(v6);
  CHECK(v6->host == "::1");
  CHECK(v6->port == 7878);
}

TEST_CASE("a port that cannot exist, or no host, is refused rather than tried", "[net][flags]") {
  for (const char* bad :
       {"127.0.0.1", "127.0.0.1:", ":7878", "[]:7878", "127.0.0.1:0", "127.0.0.1:65536", "127.0.0.1:99999",
        "127.0.0.1:123456", "127.0.0.1:abc", "127.0.0.1:78x", "127.0.0.1:-1", "127.0.0.1:+80", "127.0.0.1: 80", ""}) {
    INFO("--connect " << bad);
    CHECK_FALSE(parse_host_port(bad));
  }
}

TEST_CASE("host:port is written back as --connect reads it, an IPv6 address in brackets", "[net][flags]") {
  CHECK(fishtank::host_port_text("127.0.0.1", "7878") == "127.0.0.1:7878");
  CHECK(fishtank::host_port_text("::1", "7878") == "[::1]:7878");
  for (const char* text : {"tank.example:80", "[::1]:7878", "[fe80::1]:1"}) {
    const auto parsed = parse_host_port(text);
    REQUIRE(parsed);
    CHECK(fishtank::host_port_text(parsed->host, std::to_string(parsed->port)) == text);
  }
}
