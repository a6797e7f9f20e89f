// The one result vocabulary of libcosmic: a value, or an Error that says what failed, why, the
// errno where a system call failed, and the channel where the failure concerns one. In the spirit
// of std::expected (C++23) and iceoryx's expected; hot paths return it, never throw.
//
// Threads: plain values; any thread.
#pragma once

#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

#include "cosmic/event.hpp"

namespace cosmic {

// strerror(err) without strerror's shared buffer (safe on any thread).
inline std::string errno_text(int err) {
  char buffer[128];
  // GNU strerror_r returns the text, in `buffer` or a static string of its own.
  return ::strerror_r(err, buffer, sizeof buffer);
}

struct Error {
  std::string text;                // for a person: what failed and why
  int code = 0;                    // errno where a system call failed, else 0
  ChannelId channel = kNoChannel;  // the channel it concerns, where one does

  // "WHAT: <errno text>", with `err` kept in code.
  static Error from_errno(std::string_view what, int err) {
    return Error{std::string(what) + ": " + errno_text(err), err, kNoChannel};
  }
  friend bool operator==(const Error&, const Error&) = default;
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}      // NOLINT: implicit by design
  Result(Error error) : state_(std::in_place_index<1>, std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const noexcept { return state_.index() == 0; }
  explicit operator bool() const noexcept { return ok(); }
  // Only when ok().
  T& value() & { return std::get<0>(state_); }
  const T& value() const& { return std::get<0>(state_); }
  T&& value() && { return std::get<0>(std::move(state_)); }
  T value_or(T fallback) const& { return ok() ? std::get<0>(state_) : std::move(fallback); }
  // Only when !ok().
  const Error& error() const& { return std::get<1>(state_); }
  Error&& error() && { return std::get<1>(std::move(state_)); }

 private:
  std::variant<T, Error> state_;
};

template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const noexcept { return !error_.has_value(); }
  explicit operator bool() const noexcept { return ok(); }
  const Error& error() const& { return *error_; }
  Error&& error() && { return std::move(*error_); }

 private:
  std::optional<Error> error_;
};

}  // namespace cosmic
