// The configure() plan of the adapters' kit (cosmic/binding_plan.hpp): the shared checks, one
// refusal per channel, the joined reasons and the diff against what was carried.
#include "cosmic/binding_plan.hpp"

#include <gtest/gtest.h>

namespace cosmic {
namespace {

ChannelBinding binding(ChannelId id, std::string name, HopRole role, std::uint64_t payload = 8) {
  ChannelBinding b;
  b.id = id;
  b.spec.name = std::move(name);
  b.spec.payload = payload;
  b.role = role;
  return b;
}

std::vector<ChannelId> ids(const std::vector<const ChannelBinding*>& bindings) {
  std::vector<ChannelId> out;
  for (const ChannelBinding* b : bindings) out.push_back(b->id);
  return out;
}

TEST(BindingPlan, AcceptsEveryWellFormedBindingInOrder) {
  const std::vector<ChannelBinding> given{binding(2, "b", HopRole::subscriber), binding(1, "a", HopRole::publisher),
                                          binding(2, "b", HopRole::publisher)};
  const BindingPlan plan(given);
  EXPECT_EQ(ids(plan.accepted()), (std::vector<ChannelId>{2, 1, 2}));
  const Status status = plan.status();
  EXPECT_TRUE(status.ok);
  EXPECT_TRUE(status.error.empty());
  EXPECT_TRUE(status.refused.empty());
}

TEST(BindingPlan, RefusesBindingsWithoutIdOrNameOneByOne) {
  const std::vector<ChannelBinding> given{binding(kNoChannel, "x", HopRole::subscriber),
                                          binding(kNoChannel, "y", HopRole::subscriber),
                                          binding(4, "", HopRole::publisher), binding(5, "kept", HopRole::publisher)};
  const BindingPlan plan(given);
  EXPECT_EQ(ids(plan.accepted()), (std::vector<ChannelId>{5}));
  const Status status = plan.status();
  EXPECT_FALSE(status.ok);
  ASSERT_EQ(status.refused.size(), 3u);
  EXPECT_EQ(status.error,
            "channel x: the binding has no channel id or name; channel y: the binding has no channel id or name; "
            "channel (unnamed, id 4): the binding has no channel id or name");
}

TEST(BindingPlan, AChannelBoundTwiceInOneRoleIsRefusedOnceInEveryRole) {
  const std::vector<ChannelBinding> given{binding(1, "a", HopRole::publisher), binding(1, "a", HopRole::subscriber),
                                          binding(1, "a", HopRole::subscriber), binding(1, "a", HopRole::subscriber),
                                          binding(2, "b", HopRole::subscriber)};
  const BindingPlan plan(given);
  EXPECT_EQ(ids(plan.accepted()), (std::vector<ChannelId>{2}));
  const Status status = plan.status();
  ASSERT_EQ(status.refused.size(), 1u);
  EXPECT_EQ(status.refused[0].channel, 1u);
  EXPECT_EQ(status.error, "channel a: bound twice as subscriber");
}

TEST(BindingPlan, ATransportRefusalKeepsTheFirstReasonAndTakesTheChannelOutOfEveryRole) {
  const std::vector<ChannelBinding> given{binding(1, "a", HopRole::publisher), binding(1, "a", HopRole::subscriber),
                                          binding(2, "b", HopRole::subscriber)};
  BindingPlan plan(given);
  plan.refuse(given[1], "no writer");
  plan.refuse(given[0], "no reader");
  EXPECT_TRUE(plan.refused(1));
  EXPECT_FALSE(plan.refused(2));
  EXPECT_EQ(ids(plan.accepted()), (std::vector<ChannelId>{2}));
  EXPECT_EQ(plan.status().error, "channel a: no writer");
  ASSERT_EQ(plan.carried().size(), 1u);
  EXPECT_EQ(plan.carried()[0].spec.name, "b");
}

TEST(BindingPlan, DiffNamesWhatIsAddedChangedAndRemovedByChannelAndRole) {
  const std::vector<ChannelBinding> before{binding(1, "a", HopRole::subscriber), binding(2, "b", HopRole::subscriber),
                                           binding(3, "c", HopRole::publisher), binding(4, "d", HopRole::publisher)};
  const std::vector<ChannelBinding> given{binding(1, "a", HopRole::subscriber),      // kept as it was
                                          binding(2, "b", HopRole::subscriber, 64),  // changed: payload
                                          binding(3, "c", HopRole::subscriber),      // new role: added
                                          binding(5, "e", HopRole::publisher),       // added
                                          binding(4, "d", HopRole::publisher),
                                          binding(4, "d", HopRole::publisher)};
  const BindingPlan plan(given);  // d is refused (bound twice): it counts as removed
  const BindingDiff diff = plan.diff(before);
  EXPECT_EQ(ids(diff.added), (std::vector<ChannelId>{3, 5}));
  EXPECT_EQ(ids(diff.changed), (std::vector<ChannelId>{2}));
  ASSERT_EQ(diff.removed.size(), 2u);
  EXPECT_EQ(diff.removed[0].id, 3u);
  EXPECT_EQ(diff.removed[0].role, HopRole::publisher);
  EXPECT_EQ(diff.removed[1].id, 4u);
  EXPECT_FALSE(diff.empty());
  EXPECT_TRUE(BindingPlan(before).diff(before).empty());
}

TEST(BindingPlan, ACanPlanThatMovedIsAChange) {
  ChannelBinding planned = binding(1, "a", HopRole::subscriber);
  planned.can = CanHopPlan{};
  planned.can->etag = 300;
  ChannelBinding moved = planned;
  moved.can->etag = 301;
  const std::vector<ChannelBinding> before{planned};
  const std::vector<ChannelBinding> given{moved};
  EXPECT_EQ(ids(BindingPlan(given).diff(before).changed), (std::vector<ChannelId>{1}));
}

TEST(BindingPlan, NotStartedIsAFailureOfTheWholeSegment) {
  const Status status = not_started("bus");
  EXPECT_FALSE(status.ok);
  EXPECT_TRUE(status.refused.empty());
  EXPECT_EQ(status.error, "segment bus is not started");
}

}  // namespace
}  // namespace cosmic
