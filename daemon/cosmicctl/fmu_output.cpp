#include "fmu_output.hpp"

#include <filesystem>
#include <iostream>
#include <string>

#include "bind_output.hpp"
#include "cosmic/report.hpp"
#include "cosmic/units.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;
using cosmic::pad_column;

// "412 us (4.1%)": the worst step and its share of the step.
std::string worst_text(const Json& report) {
  const double share = report["worst_step_ns"].get<double>() / report["step_ns"].get<double>();
  return nanos_text(report["worst_step_ns"]) + " (" + cosmic::format_percent(share) + ")";
}

// "0.4s ago", "stale (12s ago)" past three seconds, or "no report".
std::string report_age(const Json& report) {
  if (report.is_null()) return "no report";
  const std::string age = age_text(report["age_s"].get<double>());
  return report["stale"].get<bool>() ? "stale (" + age + ")" : age;
}

std::string skipped_text(const Json& skipped) {
  std::string out;
  for (const auto& [input, count] : skipped.items()) {
    if (count.get<std::uint64_t>() > 0) out += (out.empty() ? "" : ", ") + input + "=" + count.dump();
  }
  return out;
}

}  // namespace

void print_fmus(const Json& answer) {
  std::cout << pad_column("FMU", 16) << pad_column("FILE", 18) << pad_column("FMI", 5) << pad_column("SEGMENT", 12)
            << pad_column("STEP", 9) << pad_column("STATE", 10) << pad_column("STEPS", 10) << pad_column("LATE", 7)
            << pad_column("WORST (OF STEP)", 19) << "REPORT\n";
  for (const auto& f : answer["fmus"]) {
    const Json& r = f["report"];
    const bool reported = !r.is_null();
    std::cout << pad_column(text(f["name"]), 16)
              << pad_column(std::filesystem::path(text(f["fmu"])).filename().string(), 18)
              << pad_column(text(f["fmi_version"]), 5) << pad_column(text(f["segment"]), 12)
              << pad_column(nanos_text(f["step_ns"]), 9) << pad_column(reported ? text(r["state"]) : "-", 10)
              << pad_column(reported ? text(r["steps"]) : "-", 10)
              << pad_column(reported ? text(r["late_steps"]) : "-", 7) << pad_column(reported ? worst_text(r) : "-", 19)
              << report_age(r) << "\n";
    if (reported && r["step_ns"] != f["step_ns"])
      std::cout << "    the runner steps every " << nanos_text(r["step_ns"]) << " (not the configuration's)\n";
    if (!f["overrun"].is_null()) {
      std::string channels;
      for (const auto& c : f["publishes"]) channels += (channels.empty() ? "" : ", ") + text(c);
      std::cout << "    ! " << text(f["overrun"]) << ": its output channels are flagged violated (" << channels
                << ")\n";
    }
    if (reported && !skipped_text(r["skipped"]).empty())
      std::cout << "    skipped input events: " << skipped_text(r["skipped"]) << "\n";
    if (reported && r["state"] == "failed" && !text(r["message"]).empty())
      std::cout << "    its last log lines:\n      " << text(r["message"]) << "\n";
  }
}

void print_channel_fmus(const Json& fmus) {
  if (fmus.empty()) return;
  std::cout << "\nfmus:\n";
  for (const auto& f : fmus) {
    std::cout << "  " << text(f["name"]) << (f["role"] == "publisher" ? " publishes" : " subscribes") << " on "
              << text(f["segment"]) << ", step " << nanos_text(f["step_ns"]) << ": ";
    const Json& r = f["report"];
    if (r.is_null()) {
      std::cout << "no report\n";
      continue;
    }
    std::cout << text(r["state"]) << ", worst step " << worst_text(r) << ", " << text(r["late_steps"])
              << " late steps, report " << report_age(r) << "\n";
    if (!f["overrun"].is_null()) std::cout << "    ! " << text(f["overrun"]) << "\n";
  }
}

}  // namespace cosmicctl
