#include "metrics_exposition.hpp"

#include <charconv>
#include <cmath>

namespace cosmicd {
namespace {

const char* type_name(MetricType type) {
  switch (type) {
    case MetricType::counter:
      return "counter";
    case MetricType::histogram:
      return "histogram";
    case MetricType::gauge:
      break;
  }
  return "gauge";
}

// Label values escape backslash, double quote and newline in both formats.
void append_escaped(std::string& out, std::string_view value) {
  for (const char c : value) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '"') {
      out += "\\\"";
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
}

void append_label(std::string& out, bool& first, std::string_view name, std::string_view value) {
  out += first ? '{' : ',';
  first = false;
  out += name;
  out += "=\"";
  append_escaped(out, value);
  out += '"';
}

}  // namespace

const char* content_type(ExpositionFormat format) {
  return format == ExpositionFormat::openmetrics ? "application/openmetrics-text; version=1.0.0; charset=utf-8"
                                                 : "text/plain; version=0.0.4; charset=utf-8";
}

ExpositionFormat format_for_accept(std::string_view accept) {
  return accept.find("application/openmetrics-text") != std::string_view::npos ? ExpositionFormat::openmetrics
                                                                               : ExpositionFormat::prometheus_text;
}

std::string format_number(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  char buffer[32];
  // General notation (as %g, shortest round trip): 0.0005 stays readable, 5e-06 is short.
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general);
  return std::string(buffer, result.ptr);
}

void Exposition::family(std::string_view name, MetricType type, std::string_view help) {
  name_ = name;
  type_ = type;
  // The text format 0.0.4 declares a counter under its sample name; OpenMetrics under the
  // family name without "_total".
  const std::string declared =
      type == MetricType::counter && format_ == ExpositionFormat::prometheus_text ? name_ + "_total" : name_;
  out_ += "# HELP " + declared + " ";
  out_ += help;
  out_ += "\n# TYPE " + declared + " " + type_name(type) + "\n";
}

void Exposition::line(std::string_view suffix, const Labels& labels, std::string_view value,
                      const std::pair<std::string_view, std::string>* extra) {
  out_ += name_;
  out_ += suffix;
  bool first = true;
  for (const auto& [label, text] : labels) append_label(out_, first, label, text);
  if (extra) append_label(out_, first, extra->first, extra->second);
  if (!first) out_ += '}';
  out_ += ' ';
  out_ += value;
  out_ += '\n';
}

void Exposition::sample(const Labels& labels, std::uint64_t value) {
  line(type_ == MetricType::counter ? "_total" : "", labels, std::to_string(value));
}

void Exposition::sample(const Labels& labels, double value) {
  line(type_ == MetricType::counter ? "_total" : "", labels, format_number(value));
}

void Exposition::histogram(const Labels& labels, const std::vector<double>& upper_bounds,
                           const std::vector<std::uint64_t>& cumulative) {
  for (std::size_t i = 0; i < cumulative.size(); ++i) {
    const std::pair<std::string_view, std::string> le{
        "le", i < upper_bounds.size() ? format_number(upper_bounds[i]) : "+Inf"};
    line("_bucket", labels, std::to_string(cumulative[i]), &le);
  }
  line("_count", labels, std::to_string(cumulative.empty() ? 0 : cumulative.back()));
}

std::string Exposition::finish() {
  if (format_ == ExpositionFormat::openmetrics) out_ += "# EOF\n";
  return std::move(out_);
}

}  // namespace cosmicd
