// cosmic-federation-bench: a federation of N gateways and C channels simulated in one process
// (no DDS: the announcements are encoded, delivered to every other gateway's view, decoded and
// applied, and each gateway's admission analyses its bound set again with what the others reserve,
// exactly as cosmicd does on each tick). Prints, for the start (every gateway announces) and for one
// gateway leaving: rounds until no announcement changes, announcements and bytes sent, and the
// processing time per gateway per round (p50, max): the compute part of the convergence time, to
// which the federation network's delivery time is added once per round.
//   cosmic-federation-bench [--gateways N] [--channels C] [--shared-can-every K]
// Topology: one DDS backbone all gateways attach (1 Gbit/s), one LCM edge per gateway, and a CAN bus
// (500 kbit/s) shared by each pair of neighbouring gateways. Each gateway carries C/N channels: two
// thirds from its edge to the backbone, one third from the backbone to its shared CAN bus.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "cosmic/federation.hpp"
#include "cosmic/federation_view.hpp"
#include "cosmic/knowledge_base.hpp"

namespace {

using namespace std::chrono_literals;
using cosmic::Nanos;
using Clock = std::chrono::steady_clock;

struct Gateway {
  cosmic::GatewayIdentity identity;
  std::unique_ptr<cosmic::KnowledgeBase> kb;
  std::unique_ptr<cosmic::FederationView> view;
  std::uint64_t revision = 0;
  std::optional<cosmic::Announcement> announced;  // revision 0, to compare
  bool alive = true;
};

cosmic::SegmentSpec segment(const std::string& name, cosmic::SegmentType type) {
  cosmic::SegmentSpec s;
  s.name = name;
  s.type = type;
  s.max_utilization = 0.7;
  s.latency_bound = Nanos(2ms);
  return s;
}

std::vector<cosmic::SegmentSpec> segments_of(std::size_t g) {
  cosmic::SegmentSpec backbone = segment("backbone", cosmic::SegmentType::dds);
  backbone.bandwidth = cosmic::BitRate{1'000'000'000};
  cosmic::SegmentSpec edge = segment("edge", cosmic::SegmentType::lcm);
  edge.lcm.url = "udpm://239.255.76.67:" + std::to_string(8000 + g) + "?ttl=0";
  edge.reliability = cosmic::Reliability::best_effort;
  cosmic::SegmentSpec bus = segment("bus", cosmic::SegmentType::can);
  bus.can.interface = "can0";
  bus.can.bitrate = cosmic::BitRate{500'000};
  bus.can.data_bitrate = bus.can.bitrate;
  bus.network = "bus-" + std::to_string(g / 2);  // gateways 2k and 2k+1 share a bus
  return {backbone, edge, bus};
}

cosmic::ChannelSpec channel_of(std::size_t g, std::size_t i, bool to_can) {
  cosmic::ChannelSpec c;
  c.name = "g" + std::to_string(g) + "c" + std::to_string(i);
  c.subject = (static_cast<std::uint64_t>(g) << 32) | i;
  c.cls = cosmic::ChannelClass::srt;
  c.payload = 8;
  c.period = Nanos(to_can ? 200ms : 10ms);
  c.reaction_time = Nanos(100ms);
  c.omission_degree = 1;
  c.publishers = {to_can ? "backbone" : "edge"};
  c.subscribers = {to_can ? "bus" : "backbone"};
  return c;
}

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct Round {
  std::size_t announcements = 0;
  std::size_t bytes = 0;
  std::vector<double> work;  // per gateway, seconds
};

// Every alive gateway whose announcement changed publishes it; every other alive gateway applies
// what was published and re-analyses. Returns what the round cost.
Round run_round(std::vector<Gateway>& gateways, std::vector<cosmic::FederationMessage>& extra, Nanos now) {
  Round round;
  std::vector<cosmic::FederationMessage> published = std::move(extra);
  extra.clear();
  for (std::size_t g = 0; g < gateways.size(); ++g) {
    Gateway& gw = gateways[g];
    if (!gw.alive) continue;
    const auto start = Clock::now();
    cosmic::Announcement a = cosmic::announcement_of(gw.identity, *gw.kb, 0);
    if (!gw.announced || *gw.announced != a) {
      gw.announced = a;
      a.revision = ++gw.revision;
      std::string body = cosmic::encode(a);
      round.bytes += body.size();
      ++round.announcements;
      published.push_back(
          {cosmic::FederationMessage::Kind::announcement, "w" + std::to_string(g), gw.identity.id, std::move(body)});
    }
    round.work.push_back(seconds(Clock::now() - start));
  }
  if (published.empty()) return round;
  std::size_t w = 0;
  for (std::size_t g = 0; g < gateways.size(); ++g) {
    Gateway& gw = gateways[g];
    if (!gw.alive) continue;
    const auto start = Clock::now();
    bool changed = false;
    for (const auto& m : published) {
      if (m.source != "w" + std::to_string(g)) changed |= gw.view->apply(m, now);
    }
    if (changed) gw.kb->set_peer_reservations(gw.view->reservations());
    round.work[w++] += seconds(Clock::now() - start);
  }
  return round;
}

void converge(const char* what, std::vector<Gateway>& gateways, std::vector<cosmic::FederationMessage> first,
              Nanos now) {
  std::size_t rounds = 0;
  std::size_t announcements = 0;
  std::size_t bytes = 0;
  std::vector<double> per_round_max;
  std::vector<double> all;
  for (; rounds < 20; ++rounds) {
    Round r = run_round(gateways, first, now);
    if (r.announcements == 0 && rounds > 0) break;
    announcements += r.announcements;
    bytes += r.bytes;
    per_round_max.push_back(*std::max_element(r.work.begin(), r.work.end()));
    all.insert(all.end(), r.work.begin(), r.work.end());
  }
  std::sort(all.begin(), all.end());
  const double total_max = std::accumulate(per_round_max.begin(), per_round_max.end(), 0.0);
  std::printf(
      "%-28s rounds %zu  announcements %zu  bytes %zu (%.1f KiB/announcement)  per gateway and round: p50 %.2f ms, max "
      "%.2f ms;"
      "  compute to converge %.1f ms + %zu deliveries\n",
      what, rounds, announcements, bytes, announcements ? bytes / 1024.0 / announcements : 0.0,
      all.empty() ? 0 : all[all.size() / 2] * 1e3, all.empty() ? 0 : all.back() * 1e3, total_max * 1e3, rounds);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Federation of gateways at scale, simulated in one process (no DDS)"};
  std::size_t gateways_count = 50;
  std::size_t channels_count = 5000;
  app.add_option("--gateways", gateways_count, "gateways")->check(CLI::Range(2, 256));
  app.add_option("--channels", channels_count, "channels over all gateways")->check(CLI::Range(2, 100000));
  CLI11_PARSE(app, argc, argv);

  std::vector<Gateway> gateways(gateways_count);
  const std::size_t per_gateway = channels_count / gateways_count;
  const auto bind_start = Clock::now();
  std::size_t bound = 0;
  for (std::size_t g = 0; g < gateways_count; ++g) {
    Gateway& gw = gateways[g];
    gw.identity = cosmic::GatewayIdentity{0x1000 + g, "gw" + std::to_string(g)};
    cosmic::GatewaySpec spec;
    spec.name = gw.identity.name;
    spec.can_node_id = static_cast<std::uint8_t>(1 + g % 100);
    gw.kb = std::make_unique<cosmic::KnowledgeBase>(spec, segments_of(g));
    gw.view = std::make_unique<cosmic::FederationView>(gw.identity.id);
    for (std::size_t i = 0; i < per_gateway; ++i) bound += gw.kb->bind(channel_of(g, i, i % 3 == 2)).bound() ? 1 : 0;
  }
  std::printf("federation of %zu gateways, %zu channels (%zu bound), each gateway's admission alone: %.1f ms in all\n",
              gateways_count, per_gateway * gateways_count, bound, seconds(Clock::now() - bind_start) * 1e3);

  converge("start (every gateway joins)", gateways, {}, Nanos(1s));
  // Afterwards nothing is announced until something changes; what keeps each gateway alive to the
  // others is its participant's DDS announcements, every lease / 3.
  std::printf(
      "%-28s 0 announcements; DDS participant announcements %.0f/s on the federation domain with lease 3 s "
      "(each gateway every lease / 3)\n",
      "steady state", static_cast<double>(gateways_count) / 1.0);
  // One gateway leaves: it withdraws; every other releases what it reserved and may re-announce.
  gateways[gateways_count / 2].alive = false;
  converge("one gateway leaves", gateways,
           {{cosmic::FederationMessage::Kind::withdrawn, "w" + std::to_string(gateways_count / 2), 0, {}}}, Nanos(2s));
  return 0;
}
