// Writer of the Prometheus text exposition format (0.0.4) and of OpenMetrics 1.0 text, which
// differ only in how counters are declared and in OpenMetrics' closing "# EOF". Pure string
// building: no I/O, any thread, one writer per rendering.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cosmicd {

enum class ExpositionFormat { prometheus_text, openmetrics };

// HTTP Content-Type of each format.
const char* content_type(ExpositionFormat format);
// The format a scraper asks for in its Accept header (OpenMetrics when it lists it).
ExpositionFormat format_for_accept(std::string_view accept);

enum class MetricType { counter, gauge, histogram };

using Labels = std::vector<std::pair<std::string_view, std::string>>;

class Exposition {
 public:
  explicit Exposition(ExpositionFormat format) : format_(format) {}

  // Starts a metric family. `name` is the family name: counters without "_total" (sample()
  // adds it), histograms without "_bucket"/"_count". Samples of a family follow its family().
  void family(std::string_view name, MetricType type, std::string_view help);
  // One sample of the current family (counters: NAME_total; gauges: NAME).
  void sample(const Labels& labels, std::uint64_t value);
  void sample(const Labels& labels, double value);
  // A histogram's cumulative bucket counts: cumulative[i] against upper_bounds[i] (finite, in
  // the family's unit), then one more for +Inf, which is also written as NAME_count.
  void histogram(const Labels& labels, const std::vector<double>& upper_bounds,
                 const std::vector<std::uint64_t>& cumulative);

  // The document; the writer is spent afterwards.
  std::string finish();

 private:
  void line(std::string_view suffix, const Labels& labels, std::string_view value,
            const std::pair<std::string_view, std::string>* extra = nullptr);

  ExpositionFormat format_;
  std::string out_;
  std::string name_;
  MetricType type_ = MetricType::gauge;
};

// Shortest text that reads back to `value`; "+Inf", "-Inf", "NaN" as both formats spell them.
std::string format_number(double value);

}  // namespace cosmicd
