// cosmic-federation-peer: writes one announcement on the federation topic the way a gateway does
// (cosmic::make_dds_federation_link), so tests can play a stranger, a spoofer or a broken peer.
//   cosmic-federation-peer --domain N --key HEX16 [--body-file FILE]
// Reads the body from FILE (or the first line of stdin), publishes it under KEY, prints READY, and
// keeps it published (and its liveliness asserted) until it is killed (with --body-file) or until
// stdin closes.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

#include "cosmic/dds_federation_link.hpp"

namespace {

class StderrLogger final : public cosmic::Logger {
 public:
  void log(cosmic::LogLevel, std::string_view message) override { std::cerr << message << "\n"; }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Publishes one federation announcement, as a gateway would"};
  unsigned domain = 0;
  std::string key_text;
  std::string body_file;
  app.add_option("--domain", domain, "DDS domain")->required();
  app.add_option("--key", key_text, "the gateway id the sample is filed under (16 hex digits)")->required();
  app.add_option("--body-file", body_file, "the announcement's text (default: stdin up to an empty line)");
  CLI11_PARSE(app, argc, argv);
  std::string body;
  if (!body_file.empty()) {
    std::ifstream in(body_file);
    body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } else {
    std::getline(std::cin, body);
  }
  cosmic::SegmentSpec segment;
  segment.name = "federation";
  segment.type = cosmic::SegmentType::dds;
  segment.dds.domain = domain;
  StderrLogger log;
  cosmic::FederationSpec federation;
  federation.segment = segment.name;
  federation.lease = cosmic::Nanos(1'000'000'000);
  auto link = cosmic::make_dds_federation_link(segment, cosmic::GatewayIdentity{1, "federation-peer"}, federation, log);
  if (const std::string error = link->start(); !error.empty()) {
    std::cerr << "cosmic-federation-peer: " << error << "\n";
    return 1;
  }
  if (!link->publish(std::stoull(key_text, nullptr, 16), body)) {
    std::cerr << "cosmic-federation-peer: write failed\n";
    return 1;
  }
  std::cout << "READY" << std::endl;
  if (!body_file.empty()) {
    for (;;) ::pause();
  }
  std::string line;
  while (std::getline(std::cin, line)) {
  }
  return 0;
}
