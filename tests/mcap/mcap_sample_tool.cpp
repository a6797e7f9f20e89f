// The C++ side of the MCAP interoperability test (mcap_interop.cjs runs it):
//   mcap_sample_tool write FILE.mcap EXPECTED.json   the deterministic sample (two schemas, ros2msg
//                                                    and jsonschema, three channels, 3000 messages,
//                                                    zstd, 4 KiB chunks) and what it holds, as JSON
//   mcap_sample_tool dump FILE.mcap                  what read_mcap finds in a file, as JSON
// Both JSON documents have the same shape, so the script compares what either side wrote with
// what the other read: times as decimal strings (they exceed a double), bytes as hex.
// Exit status: 0, 1 when the file cannot be read or written (the reason on stderr), 64 on bad usage.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../unit/mcap_test_support.hpp"
#include "cosmic/mcap_reader.hpp"

namespace {

using cosmic::mcap_test::Bytes;
using nlohmann::json;

std::string hex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string text;
  for (const std::uint8_t b : bytes) text += {kDigits[b >> 4], kDigits[b & 15]};
  return text;
}

json contents(const cosmic::McapHeader& header, const std::vector<cosmic::McapSchema>& schemas,
              const std::vector<cosmic::McapChannel>& channels, const std::vector<cosmic::McapMetadata>& metadata,
              const std::vector<cosmic::McapMessage>& messages) {
  json out{{"header", {{"profile", header.profile}, {"library", header.library}}},
           {"schemas", json::array()},
           {"channels", json::array()},
           {"metadata", json::array()},
           {"messages", json::array()}};
  for (const auto& s : schemas)
    out["schemas"].push_back({{"id", s.id}, {"name", s.name}, {"encoding", s.encoding}, {"data", hex(s.data)}});
  for (const auto& c : channels)
    out["channels"].push_back({{"id", c.id},
                               {"schemaId", c.schema_id},
                               {"topic", c.topic},
                               {"messageEncoding", c.message_encoding},
                               {"metadata", c.metadata}});
  for (const auto& m : metadata) out["metadata"].push_back({{"name", m.name}, {"metadata", m.metadata}});
  for (const auto& m : messages)
    out["messages"].push_back({{"channelId", m.channel_id},
                               {"sequence", m.sequence},
                               {"logTime", std::to_string(m.log_time)},
                               {"publishTime", std::to_string(m.publish_time)},
                               {"data", hex(m.data)}});
  return out;
}

int write_sample(const char* mcap_path, const char* json_path) {
  using namespace cosmic;
  const auto sample = mcap_test::write_sample(mcap_test::small_chunks(McapCompression::zstd, 4096), 3000);
  std::ofstream mcap(mcap_path, std::ios::binary);
  mcap.write(reinterpret_cast<const char*>(sample.written.file.data()),
             static_cast<std::streamsize>(sample.written.file.size()));
  std::ofstream expected(json_path);
  expected << contents(McapHeader{"x-cosmic", "cosmic-gateway"}, sample.schemas, sample.channels, {sample.metadata},
                       sample.messages)
           << "\n";
  if (!mcap || !expected) {
    std::cerr << "mcap_sample_tool: cannot write " << mcap_path << " or " << json_path << "\n";
    return 1;
  }
  return 0;
}

int dump(const char* mcap_path) {
  std::ifstream in(mcap_path, std::ios::binary);
  if (!in) {
    std::cerr << "mcap_sample_tool: cannot read " << mcap_path << "\n";
    return 1;
  }
  const Bytes file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto read = cosmic::read_mcap(file);
  if (!read) {
    std::cerr << "mcap_sample_tool: " << mcap_path << ": " << read.error().text << "\n";
    return 1;
  }
  const cosmic::McapFile& f = read.value();
  json out = contents(f.header, f.schemas, f.channels, f.metadata, f.messages);
  out["truncated"] = f.truncated;
  out["truncation"] = f.truncation;
  if (f.summary && f.summary->statistics) out["statisticsMessageCount"] = f.summary->statistics->message_count;
  std::cout << out << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string command = argc > 1 ? argv[1] : "";
  if (command == "write" && argc == 4) return write_sample(argv[2], argv[3]);
  if (command == "dump" && argc == 3) return dump(argv[2]);
  std::cerr << "usage: mcap_sample_tool write FILE.mcap EXPECTED.json | dump FILE.mcap\n";
  return 64;
}
