// bind --replace made before break (issue 40): the replacement's new hops are opened beside the
// running ones, the old publishers keep feeding the channel, and the switch waits, at most the
// request's match timeout, until every new publisher hop with discovery (DDS) has matched a
// remote writer. Control thread only; the wait is a chain of short sleeps on the offload worker,
// each followed by a look at the match counts here.
#include <chrono>
#include <cstdio>
#include <thread>

#include "cosmic/control_protocol.hpp"

#include "bind_answer.hpp"

namespace cosmic {

using Json = nlohmann::json;
using Steady = std::chrono::steady_clock;

namespace {
constexpr auto kMatchPoll = std::chrono::milliseconds(2);
}  // namespace

struct ControlProtocol::SwitchWait {
  std::shared_ptr<BindPlan> plan;
  Json request;
  std::string command;
  Reply later;
  Steady::time_point prepared_at;
  Nanos timeout;
};

ControlProtocol::Answer ControlProtocol::switch_planned(std::shared_ptr<BindPlan> plan, const Json& request,
                                                        const std::string& command, bool replan, const Reply& later) {
  if (replan && plan->generation != gateway_.generation()) {
    // Reservations changed while the federation claimed the networks: admitted again, as commit_planned does.
    auto fresh = std::make_shared<BindPlan>(gateway_.replace_plan_input(plan->channels));
    Gateway::plan_replace(*fresh);
    plan = std::move(fresh);
  }
  const double seconds = request.value("match_timeout_s", kDefaultMatchTimeoutS);
  auto wait = std::make_shared<SwitchWait>(
      SwitchWait{plan, request, command, later, Steady::now(),
                 std::chrono::duration_cast<Nanos>(std::chrono::duration<double>(seconds))});
  if (!gateway_.prepare_replace(*plan)) return switched(*wait, false);
  if (!offload_ || !later)
    return switched(*wait, !gateway_.await_new_publishers(*plan, wait->prepared_at, wait->timeout));
  char limit[32];
  std::snprintf(limit, sizeof limit, "%g", seconds);
  running_ = command + " of " + (plan->channels.empty() ? std::string() : plan->channels.front().name) +
             " (waiting up to " + limit + " s for its new publishers to match before the switch)";
  await_match(wait);
  return std::nullopt;
}

void ControlProtocol::await_match(const std::shared_ptr<SwitchWait>& wait) {
  offload_([] { std::this_thread::sleep_for(kMatchPoll); },
           [this, wait] {
             Json answer;
             try {
               const bool matched = Gateway::all_matched(gateway_.new_publishers(*wait->plan));
               if (!matched && Steady::now() - wait->prepared_at < wait->timeout) {
                 await_match(wait);
                 return;
               }
               running_.clear();
               answer = switched(*wait, !matched);
             } catch (const std::exception& e) {
               running_.clear();
               abandon_replay();
               answer = failure("internal_error", e.what());
             }
             wait->later(render(answer));
           });
}

Json ControlProtocol::switched(SwitchWait& wait, bool timed_out) {
  const BindResult result = gateway_.switch_over(std::move(*wait.plan), wait.prepared_at, timed_out);
  Json answer = bind_answer(result);
  if (!result.replaced.empty()) answer["replaced"] = replaced_answer(result);
  if (result.applied) {
    answer["switch_over"] = switch_over_answer(result, wait.timeout);
    if (timed_out) {
      std::string late;
      for (const NewPublisher& p : result.new_publishers) {
        if (p.matched && *p.matched == 0) late += (late.empty() ? "" : ", ") + p.channel + " on " + p.segment;
      }
      log_.log(LogLevel::warning, wait.command + ": switched after the match timeout with no writer matched for " +
                                      late + " (events published there before discovery completes are lost)");
    }
  }
  settle_replay(wait.command, result, answer);
  return finish(wait.command, wait.request, std::move(answer));
}

}  // namespace cosmic
