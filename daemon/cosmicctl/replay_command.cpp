// `cosmicctl replay FILE ...` and `cosmicctl replay stop NAME` (issue 37, docs/recording.md): a
// recording played into the running gateway's channels in place of their publishers (or beside
// them), and taken out again, through the control protocol's replay and replay_stop.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bind_output.hpp"
#include "cosmic/units.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

struct ReplayOptions {
  std::string file;
  std::vector<std::string> channels;
  double speed = 1.0;
  bool loop = false;
  std::string start_offset;
  std::string name;
  bool alongside = false;
  bool realtime = false;
  std::string latency_bound;
  std::string match_timeout;
  std::string stop_name;
};

void print_replay(const Json& r) {
  print_verdicts(r["channels"]);
  if (r.contains("replaced")) print_replaced(r["replaced"]);
  if (r.contains("switch_over")) print_switch_over(r["switch_over"]);
  const Json& replay = r["replay"];
  std::cout << "replaying " << text(replay["file"]) << " as segment " << text(replay["name"]) << " at speed "
            << replay.value("speed", 1.0) << (replay.value("loop", false) ? ", looped" : "");
  if (replay.value("start_offset_ns", 0) > 0) std::cout << ", from " << nanos_text(replay["start_offset_ns"]);
  std::cout << "\n";
  for (const auto& s : replay.value("streams", Json::array())) {
    std::cout << "    " << text(s["channel"]) << ": " << s["events"] << " events, tightest spacing "
              << nanos_text(s["tightest_ns"]) << "\n";
  }
  std::cout << "stop it with: cosmicctl replay stop " << text(replay["name"]) << "\n";
}

void print_stopped(const Json& r) {
  if (!r["channels"].empty()) print_verdicts(r["channels"]);
  if (r.contains("replaced")) print_replaced(r["replaced"]);
  const Json& replay = r["replay"];
  std::cout << "stopped replay " << text(replay["name"]);
  if (replay.contains("segment_kept")) {
    std::cout << "; its segment stays: " << text(replay["segment_kept"]);
  }
  std::cout << "\n";
}

int build_replay(const ReplayOptions& o, Json& req) {
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(o.file, error);
  if (error) {
    std::cerr << "cosmicctl: " << o.file << ": " << error.message() << "\n";
    return kExitUsage;
  }
  if (!is_utf8("file name " + o.file, absolute.string())) return kExitUsage;
  Json segment{{"file", absolute.lexically_normal().string()}, {"speed", o.speed}, {"loop", o.loop}};
  if (!o.channels.empty()) segment["channels"] = o.channels;
  for (const auto& c : o.channels)
    if (!is_utf8("channel " + c, c)) return kExitUsage;
  if (!o.start_offset.empty()) segment["start_offset"] = o.start_offset;
  if (!o.name.empty()) segment["name"] = o.name;
  if (o.realtime) segment["realtime"] = true;
  if (!o.latency_bound.empty()) segment["latency_bound"] = o.latency_bound;
  req = {{"command", "replay"}, {"segment", segment}, {"mode", o.alongside ? "alongside" : "replace"}};
  if (!o.match_timeout.empty()) {
    const auto timeout = cosmic::parse_duration(o.match_timeout);
    if (!timeout.value || *timeout.value > std::chrono::seconds(60)) {
      std::cerr << "cosmicctl: --match-timeout: '" << o.match_timeout
                << "' is not a duration from 0 to 60s (e.g. 500ms, 10s)\n";
      return kExitUsage;
    }
    req["match_timeout_s"] = std::chrono::duration<double>(*timeout.value).count();
  }
  return kExitOk;
}

}  // namespace

std::vector<CommandRunner> add_replay_command(CLI::App& app, const GlobalOptions& options) {
  auto o = std::make_shared<ReplayOptions>();
  auto* replay = app.add_subcommand(
      "replay",
      "Play a recording (an MCAP file cosmicd recorded) into the running gateway's channels in place of their "
      "publishers, admitted as any publisher; `replay stop NAME` puts them back");
  replay->add_option("FILE", o->file, "The recording")->check(CLI::ExistingFile);
  replay->add_option("--channel", o->channels, "A recorded channel to replay (name or glob; repeat; default: all)");
  replay->add_option("--speed", o->speed, "1 as recorded, 2 twice as fast (0.001 to 1000)");
  replay->add_flag("--loop", o->loop, "Play the recording again when it ends");
  replay->add_option("--start-offset", o->start_offset, "Start this far into the recording, e.g. 2s");
  replay->add_option("--name", o->name, "The replay segment's name (default replay-N)");
  replay->add_flag("--realtime", o->realtime,
                   "Declare the replay real-time (it plays at the receive threads' priority): needed for hrt channels");
  replay->add_option("--latency-bound", o->latency_bound,
                     "What the replay's timer may add to the recorded spacing, at worst (default 1ms)");
  replay->add_flag("--alongside", o->alongside, "Add the replay beside the channels' publishers instead of in place");
  replay->add_option("--match-timeout", o->match_timeout,
                     "How long the switch waits for new publishers to match (as bind --replace; default 5s)");
  auto* stop = replay->add_subcommand("stop", "End a run-time replay: the channels' publishers back, the segment gone");
  stop->add_option("NAME", o->stop_name, "The replay segment's name")->required();
  std::vector<CommandRunner> runners;
  runners.push_back(add_request_command(
      app, options, stop,
      [o](Json& req) {
        if (!is_utf8("replay name", o->stop_name)) return kExitUsage;
        req = {{"command", "replay_stop"}, {"name", o->stop_name}};
        return kExitOk;
      },
      print_stopped));
  auto start = add_request_command(
      app, options, replay, [o](Json& req) { return build_replay(*o, req); }, print_replay);
  runners.push_back([replay, stop, o, start]() -> int {
    if (!replay->parsed() || stop->parsed()) return -1;
    if (o->file.empty()) {
      std::cerr << "cosmicctl: replay: a recording FILE (or `replay stop NAME`) is required\n";
      return kExitUsage;
    }
    return start();
  });
  return runners;
}

}  // namespace cosmicctl
