// `cosmicctl record info FILE` (issue 37, docs/recording.md): what a recording holds, read offline
// from the file mapped into memory (cosmic/recording_info.hpp), as text or --json.

#include <cstdio>
#include <ctime>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "cosmic/mapped_file.hpp"
#include "cosmic/recording_info.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

// "2026-11-30T02:55:01.123Z"
std::string utc_text(std::uint64_t ns) {
  const std::time_t seconds = static_cast<std::time_t>(ns / 1'000'000'000);
  std::tm parts{};
  ::gmtime_r(&seconds, &parts);
  char text[40];
  const std::size_t n = std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &parts);
  std::snprintf(text + n, sizeof text - n, ".%03uZ", static_cast<unsigned>((ns / 1'000'000) % 1000));
  return text;
}

std::string seconds_text(std::uint64_t ns) {
  char text[32];
  std::snprintf(text, sizeof text,
                ns >= 10'000'000'000ull ? "%.1f s"
                : ns >= 1'000'000       ? "%.3f s"
                                        : "%.6f s",
                static_cast<double>(ns) / 1e9);
  return text;
}

Json info_json(const std::string& file, const cosmic::RecordingInfo& info) {
  Json streams = Json::array();
  for (const auto& s : info.streams) {
    streams.push_back({{"channel", s.topic},
                       {"segment", s.segment},
                       {"origin", s.origin},
                       {"encoding", s.encoding},
                       {"messages", s.messages},
                       {"bytes", s.bytes},
                       {"first_ns", s.first_ns},
                       {"last_ns", s.last_ns},
                       {"rate_hz", s.rate_hz()},
                       {"largest_gap_ns", s.largest_gap_ns},
                       {"missing", s.missing}});
  }
  Json closing = Json::object();
  for (const auto& [key, value] : info.closing) closing[key] = value;
  return {{"file", file},
          {"whole", info.whole},
          {"truncation", info.truncation},
          {"profile", info.profile},
          {"library", info.library},
          {"gateway", info.gateway},
          {"messages", info.messages},
          {"chunks", info.chunks},
          {"start_ns", info.start_ns},
          {"end_ns", info.end_ns},
          {"compressed_bytes", info.compressed_bytes},
          {"uncompressed_bytes", info.uncompressed_bytes},
          {"closing", closing},
          {"streams", streams}};
}

void print_info(const std::string& file, const cosmic::RecordingInfo& info) {
  std::cout << file << ": " << (info.whole ? "whole" : "cut short (" + info.truncation + ")") << "\n";
  std::cout << "recorded by " << (info.gateway.empty() ? "?" : info.gateway) << " (" << info.library << ", profile "
            << info.profile << ")\n";
  if (info.messages > 0) {
    std::cout << "span: " << utc_text(info.start_ns) << " .. " << utc_text(info.end_ns) << " ("
              << seconds_text(info.end_ns - info.start_ns) << ")\n";
  }
  std::cout << info.messages << " messages in " << info.chunks << " chunk(s)";
  if (info.compressed_bytes > 0) {
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%.1f",
                  static_cast<double>(info.uncompressed_bytes) / static_cast<double>(info.compressed_bytes));
    std::cout << ", compression " << ratio << ":1";
  }
  std::cout << "\n";
  if (!info.closing.empty()) {
    const auto at = [&](const char* key) {
      const auto it = info.closing.find(key);
      return it == info.closing.end() ? std::string("?") : it->second;
    };
    std::cout << "dropped while this file was open: " << at("dropped_queue_full") << " queue full, "
              << at("dropped_not_written") << " not written, " << at("dropped_invalid") << " invalid\n";
  } else if (!info.whole) {
    std::cout << "dropped: unknown (the recorder notes its drops when it closes a file)\n";
  }
  char line[256];
  std::snprintf(line, sizeof line, "%-20s %-12s %-18s %-14s %9s %11s %10s %12s %8s\n", "CHANNEL", "SEGMENT", "ORIGIN",
                "ENCODING", "MESSAGES", "BYTES", "RATE", "LARGEST GAP", "MISSING");
  std::cout << line;
  for (const auto& s : info.streams) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%.1f/s", s.rate_hz());
    std::snprintf(line, sizeof line, "%-20s %-12s %-18s %-14s %9llu %11llu %10s %12s %8llu\n", s.topic.c_str(),
                  s.segment.c_str(), s.origin.c_str(), s.encoding.c_str(), static_cast<unsigned long long>(s.messages),
                  static_cast<unsigned long long>(s.bytes), rate, seconds_text(s.largest_gap_ns).c_str(),
                  static_cast<unsigned long long>(s.missing));
    std::cout << line;
  }
}

}  // namespace

int run_record_info(const std::string& file, bool json) {
  const auto mapped = cosmic::MappedFile::open(file);
  if (!mapped) {
    std::cerr << "cosmicctl: cannot read " << file << ": " << mapped.error().text << "\n";
    return kExitUnavailable;
  }
  const auto info = cosmic::recording_info(mapped.value()->bytes());
  if (!info) {
    std::cerr << "cosmicctl: " << file << " is not a readable MCAP recording: " << info.error().text << "\n";
    return kExitRejected;
  }
  if (json) {
    std::cout << info_json(file, info.value()).dump(2) << "\n";
  } else {
    print_info(file, info.value());
  }
  return kExitOk;
}

}  // namespace cosmicctl
