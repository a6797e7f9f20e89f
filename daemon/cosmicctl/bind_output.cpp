// The printers bind_output.hpp declares.
#include "bind_output.hpp"

#include <cstdio>

#include "cosmic/report.hpp"

namespace cosmicctl {

using Json = nlohmann::json;
using cosmic::pad_column;

std::string seconds_as_micros(double seconds) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.0fus", seconds * 1e6);
  return buffer;
}

std::string nanos_text(const Json& ns) {
  return ns.is_number() ? cosmic::format_duration(cosmic::Nanos(ns.get<std::int64_t>())) : std::string("-");
}

std::string age_text(double seconds) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, seconds < 10 ? "%.1fs ago" : "%.0fs ago", seconds);
  return buffer;
}

std::string text(const Json& value) { return value.is_string() ? value.get<std::string>() : value.dump(); }

bool is_utf8(const std::string& what, const std::string& text) {
  const auto bad = first_invalid_utf8(text);
  if (bad) std::cerr << "cosmicctl: " << what << " is not valid UTF-8 (byte " << *bad << ")\n";
  return !bad;
}

void print_verdicts(const Json& channels) {
  for (const auto& c : channels) {
    std::cout << pad_column(text(c["name"]), 20) << pad_column(text(c["class"]), 5) << text(c["verdict"]) << "\n";
    for (const auto& r : c["reasons"]) std::cout << "    - " << text(r) << "\n";
    for (const auto& hop : c["hops"]) {
      for (const auto& check : hop["checks"]) {
        if (check["check"] == "response_time" || check["check"] == "latency") {
          const bool ok = check["ok"].get<bool>();
          std::cout << "    " << text(hop["segment"]) << ": " << text(check["check"]) << " "
                    << (check["value"].is_null() ? std::string("unbounded")
                                                 : seconds_as_micros(check["value"].get<double>()))
                    << " " << (ok ? text(check["relation"]) : std::string(">")) << " "
                    << seconds_as_micros(check["limit"].get<double>()) << (ok ? "" : "  FAIL") << "\n";
        }
      }
    }
  }
}

void print_replaced(const Json& replaced) {
  auto hops = [](const Json& list) {
    std::string out;
    for (const auto& h : list)
      out += (out.empty() ? "" : ", ") + text(h["segment"]) + (h["role"] == "publisher" ? " (P)" : " (S)");
    return out.empty() ? std::string("-") : out;
  };
  for (const auto& c : replaced) {
    std::cout << "replaced " << text(c["name"]) << ":\n";
    for (const auto& change : c["changes"]) std::cout << "    " << text(change) << "\n";
    if (c["changes"].empty()) std::cout << "    (the same definition)\n";
    std::cout << "    hops kept: " << hops(c["hops"]["kept"]) << "; added: " << hops(c["hops"]["added"])
              << "; removed: " << hops(c["hops"]["removed"]) << "\n";
  }
}

void print_switch_over(const Json& s) {
  char waited[64];
  std::snprintf(waited, sizeof waited, "%.0f ms", s["waited_s"].get<double>() * 1e3);
  std::cout << "switched over after " << waited;
  if (s["publishers"].empty()) std::cout << " (no new publisher to wait for)";
  std::cout << "\n";
  for (const auto& p : s["publishers"]) {
    std::cout << "    new publisher " << text(p["segment"]) << " of " << text(p["channel"]) << ": ";
    if (p["matched"].is_null()) {
      std::cout << "no discovery on this transport (receiving since the switch)\n";
    } else if (p["matched"].get<std::size_t>() == 0) {
      std::cout << "NO writer matched within the match timeout (" << s["match_timeout_s"].get<double>()
                << " s): events published there before discovery completes are lost\n";
    } else {
      std::cout << p["matched"].get<std::size_t>() << " writer(s) matched before the switch\n";
    }
  }
}

}  // namespace cosmicctl
