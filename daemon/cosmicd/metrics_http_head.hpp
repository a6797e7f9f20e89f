// The head of one HTTP request to the metrics endpoint, read with a byte budget (docs/metrics.md:
// requests are limited to 4 KiB). Pure byte handling, no I/O: a connection feeds what it receives,
// the fuzz target (fuzz/metrics_http_fuzzer.cpp) feeds arbitrary bytes in arbitrary pieces.
//
// The head ends at the first CRLF CRLF. What it hands on to the HTTP layer (cpp-httplib) is the
// head without the fields /metrics never honours: Range and If-Range, so a scrape is always
// answered with the whole document once (issue 22, 3c: 2,700 ranges of "0-" made 54.7 MB of a
// 20 KB document).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace cosmicd {

class RequestHead {
 public:
  enum class State { incomplete, complete, too_large };

  // `limit`: the most bytes a head may have, its closing CRLF CRLF included.
  explicit RequestHead(std::size_t limit) : limit_(limit) {}

  // Takes the head's bytes from the front of `bytes`; returns how many it took. Once the head is
  // complete (or too large) it takes nothing more: the rest belongs to what follows the head.
  std::size_t feed(std::string_view bytes);

  State state() const { return state_; }
  // Bytes taken so far (a complete head: its length).
  std::size_t size() const { return text_.size(); }
  const std::string& text() const { return text_; }
  // A complete head without its Range and If-Range lines: what the HTTP layer parses.
  std::string forwarded() const;

 private:
  std::size_t limit_;
  std::string text_;
  State state_ = State::incomplete;
};

// True when a head line (without its line end) is a field /metrics never honours.
bool ignored_field(std::string_view line);

}  // namespace cosmicd
