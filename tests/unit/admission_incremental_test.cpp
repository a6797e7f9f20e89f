// Incremental admission against the whole-set analysis: over a few hundred seeded random channel
// sets (tests/unit/random_channels.hpp, 200 for binds and 100 for unbinds), every bind's answer and the bound set's
// report equal what evaluate() gives for the same set from scratch, with the same policy (a newcomer is rejected if it
// would reject a bound HRT channel). Unbinding keeps every remaining CAN identifier and never rejects or slows down a
// remaining channel.
#include <gtest/gtest.h>

#include <map>

#include "cosmic/knowledge_base.hpp"
#include "cosmic/report.hpp"
#include "random_channels.hpp"

namespace cosmic {
namespace {

using namespace cosmic::test;

constexpr int kSets = 200;

std::set<std::uint16_t> static_etags(const RandomSet& set) {
  std::set<std::uint16_t> reserved;
  for (const auto& c : set.channels) {
    if (c.etag) reserved.insert(*c.etag);
  }
  return reserved;
}

EtagMap etags_of(const KnowledgeBase& kb) {
  EtagMap etags;
  for (const auto& c : kb.bound_channels()) {
    if (const auto etag = kb.etag_of(c.name)) etags[c.name] = *etag;
  }
  return etags;
}

std::optional<std::uint16_t> etag_in(const ChannelReport& report) {
  for (const auto& hop : report.hops) {
    if (hop.can) return hop.can->etag;
  }
  return std::nullopt;
}

// What binding `newcomer` answers according to a from-scratch evaluation of the whole new set
// (kb after the bind: a bound newcomer is its last channel).
ChannelReport from_scratch(const RandomSet& set, const KnowledgeBase& kb, const ChannelSpec& newcomer,
                           std::optional<std::uint16_t> etag) {
  std::vector<ChannelSpec> channels = kb.bound_channels();
  if (!channels.empty() && channels.back().name == newcomer.name) channels.pop_back();
  channels.push_back(newcomer);
  EtagMap etags = etags_of(kb);
  if (etag) etags[newcomer.name] = *etag;
  const Evaluation whole = evaluate(set.gateway, set.segments, channels, etags);
  ChannelReport expected = whole.channels.back();
  for (std::size_t i = 0; i + 1 < whole.channels.size(); ++i) {
    const ChannelReport& existing = whole.channels[i];
    if (existing.cls != ChannelClass::hrt || existing.verdict != Verdict::rejected) continue;
    expected.verdict = Verdict::rejected;
    for (const auto& reason : existing.reasons)
      expected.reasons.push_back("would break hrt channel " + existing.name + ": " + reason);
  }
  return expected;
}

nlohmann::json whole_set_json(const RandomSet& set, const KnowledgeBase& kb) {
  const Evaluation whole = evaluate(set.gateway, set.segments, kb.bound_channels(), etags_of(kb));
  return to_json(AdmissionReport{whole.segments, whole.channels});
}

// The per-segment load and hop count that cosmicctl segments and the STATUS line read every
// tick (without building reports) are what the full report says.
void expect_cheap_counts_match_the_report(const KnowledgeBase& kb, int set) {
  const AdmissionReport report = kb.report();
  const std::vector<SegmentLoad> loads = kb.loads();
  const std::vector<std::size_t> hops = kb.hop_counts();
  ASSERT_EQ(loads.size(), report.segments.size()) << "set " << set;
  ASSERT_EQ(hops.size(), loads.size()) << "set " << set;
  for (std::size_t s = 0; s < loads.size(); ++s) {
    EXPECT_EQ(loads[s].name, report.segments[s].name) << "set " << set;
    EXPECT_EQ(loads[s].utilization, report.segments[s].utilization) << "set " << set;
    std::size_t in_report = 0;
    for (const auto& channel : report.channels) {
      for (const auto& hop : channel.hops) in_report += hop.segment == loads[s].name ? 1 : 0;
    }
    EXPECT_EQ(hops[s], in_report) << "set " << set << " segment " << loads[s].name;
  }
}

// Four blocks of 50 sets, each its own test (seconds each, even under ASan).
class IncrementalBinds : public ::testing::TestWithParam<int> {};

TEST_P(IncrementalBinds, EveryBindEqualsTheWholeSetAnalysis) {
  RandomSets sets(20261123 + static_cast<std::uint64_t>(GetParam()));
  int rejected = 0;
  int bound = 0;
  for (int n = 0; n < kSets / 4; ++n) {
    const RandomSet set = sets.next();
    KnowledgeBase kb(set.gateway, set.segments, static_etags(set));
    for (const ChannelSpec& channel : set.channels) {
      const BindOutcome out = kb.bind(channel);
      out.bound() ? ++bound : ++rejected;
      if (out.report.hops.empty()) {  // refused before analysis: duplicate subject or etag
        EXPECT_FALSE(out.bound());
        continue;
      }
      ASSERT_EQ(to_json(out.report), to_json(from_scratch(set, kb, channel, etag_in(out.report))))
          << "set " << n << " bind " << channel.name;
    }
    ASSERT_EQ(to_json(kb.report()), whole_set_json(set, kb)) << "set " << n;
    expect_cheap_counts_match_the_report(kb, n);
  }
  // The generator exercises both outcomes in quantity.
  EXPECT_GT(bound, 150);
  EXPECT_GT(rejected, 150);
}
INSTANTIATE_TEST_SUITE_P(Seeds, IncrementalBinds, ::testing::Values(0, 1, 2, 3));

std::map<std::string, ChannelReport> by_name(const AdmissionReport& report) {
  std::map<std::string, ChannelReport> out;
  for (const auto& c : report.channels) out[c.name] = c;
  return out;
}

// After an unbind nothing still bound gets a new identifier, a later bound or a worse verdict.
void expect_nothing_worse(const std::map<std::string, ChannelReport>& before, const AdmissionReport& after, int set) {
  for (const ChannelReport& now : after.channels) {
    const ChannelReport& was = before.at(now.name);
    EXPECT_LE(now.verdict, was.verdict) << "set " << set << " " << now.name;
    for (std::size_t h = 0; h < now.hops.size(); ++h) {
      const auto& hop = now.hops[h];
      if (!hop.can) continue;
      EXPECT_EQ(hop.can->can_id, was.hops[h].can->can_id) << "set " << set << " " << now.name;
      if (was.hops[h].latency) {
        ASSERT_TRUE(hop.latency.has_value()) << "set " << set << " " << now.name;
        EXPECT_LE(*hop.latency, *was.hops[h].latency) << "set " << set << " " << now.name;
      }
    }
  }
}

TEST(IncrementalAdmission, UnbindNeverWorsensWhatStaysBound) {
  RandomSets sets(777);
  for (int n = 0; n < kSets / 2; ++n) {
    const RandomSet set = sets.next();
    KnowledgeBase kb(set.gateway, set.segments, static_etags(set));
    for (const ChannelSpec& channel : set.channels) kb.bind(channel);
    // Unbind every other bound channel, oldest first.
    std::vector<std::string> names;
    for (const auto& c : kb.bound_channels()) names.push_back(c.name);
    for (std::size_t i = 0; i < names.size(); i += 2) {
      const auto before = by_name(kb.report());
      ASSERT_TRUE(kb.unbind(names[i]));
      expect_nothing_worse(before, kb.report(), n);
    }
  }
}

}  // namespace
}  // namespace cosmic
