// Bytes arriving on a connection to cosmicd's metrics endpoint (issue 22, 'Also'): the request
// head reader (4 KiB budget, Range and If-Range dropped) fed in arbitrary pieces, then cpp-httplib's
// parsing and routing of the request behind it, as MetricsHttpServer runs both for every
// connection (daemon/cosmicd/metrics_http_server.hpp). The first input byte sets the piece size.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz_input.hpp"
#include "metrics_http_head.hpp"
#include "metrics_http_server.hpp"

using cosmic::fuzz::require;
using cosmicd::RequestHead;

namespace {

constexpr std::size_t kLimit = 4096;
const std::string kText = "# HELP cosmic_up 1 while cosmicd runs\n# TYPE cosmic_up gauge\ncosmic_up 1\n";
const std::string kOpenMetrics = kText + "# EOF\n";
const std::string kRoot = "cosmicd: metrics at /metrics\n";

cosmicd::MetricsHttpServer& server() {
  static cosmicd::MetricsHttpServer* const instance = [] {
    auto* s = new cosmicd::MetricsHttpServer(cosmicd::HttpLimits{}, nullptr, nullptr);
    s->serve_metrics([](cosmicd::ExpositionFormat format) {
      return std::optional<std::string>(format == cosmicd::ExpositionFormat::openmetrics ? kOpenMetrics : kText);
    });
    return s;
  }();
  return *instance;
}

void check_head(const RequestHead& head, std::string_view bytes) {
  const std::string& text = head.text();
  require(text.size() <= kLimit);
  require(bytes.substr(0, text.size()) == text);
  const std::size_t end = text.find("\r\n\r\n");
  switch (head.state()) {
    case RequestHead::State::complete: {
      require(end + 4 == text.size());
      const std::string forwarded = head.forwarded();
      require(forwarded.size() <= text.size());
      // Whole lines go, never the blank one that ends the head.
      require(forwarded.size() >= 3 && forwarded.compare(forwarded.size() - 3, 3, "\n\r\n") == 0);
      // No line but the request line is a field /metrics ignores.
      std::size_t begin = forwarded.find('\n');
      while (begin != std::string::npos && begin + 1 < forwarded.size()) {
        const std::size_t next = forwarded.find('\n', begin + 1);
        require(!cosmicd::ignored_field(std::string_view(forwarded).substr(begin + 1, next - begin)));
        begin = next;
      }
      break;
    }
    case RequestHead::State::too_large:
      require(text.size() == kLimit && end == std::string::npos);
      break;
    case RequestHead::State::incomplete:
      require(text.size() == bytes.size() && text.size() < kLimit && end == std::string::npos);
      break;
  }
}

void check_answer(const RequestHead& head, const std::string& response) {
  if (head.state() == RequestHead::State::incomplete) {
    require(response.empty());
    return;
  }
  require(response.compare(0, 9, "HTTP/1.1 ") == 0 && response.size() >= 12);
  const std::string status = response.substr(9, 3);
  if (head.state() == RequestHead::State::too_large) {
    require(status == "431");
    return;
  }
  // Never a part of the document, never a refusal of a Range.
  require(status != "206" && status != "416");
  const std::size_t end = response.find("\r\n\r\n");
  require(end != std::string::npos);
  require(response.find("multipart/byteranges") == std::string::npos || response.find("multipart/byteranges") > end);
  // A 200 is a whole document (compressed when the request accepts gzip or br: the .so has zlib
  // and brotli).
  const std::string_view headers = std::string_view(response).substr(0, end);
  if (status == "200" && headers.find("\r\nContent-Encoding:") == std::string_view::npos) {
    const std::string body = response.substr(end + 4);
    require(body.empty() || body == kText || body == kOpenMetrics || body == kRoot);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  cosmic::fuzz::FuzzInput input(data, size);
  const std::size_t piece = input.byte() % 64 + 1;
  const auto rest = input.bytes(size);
  const std::string_view bytes(reinterpret_cast<const char*>(rest.data()), rest.size());

  RequestHead whole(kLimit);
  const std::size_t used = whole.feed(bytes);
  require(used == whole.size());
  check_head(whole, bytes);

  // Pieces as a connection receives them give the same head.
  RequestHead pieces(kLimit);
  std::size_t taken = 0;
  for (std::size_t offset = 0; offset < bytes.size(); offset += piece)
    taken += pieces.feed(bytes.substr(offset, piece));
  require(pieces.state() == whole.state() && pieces.text() == whole.text() && taken == used);

  check_answer(whole, server().answer(bytes));
  return 0;
}
