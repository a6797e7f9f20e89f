// cosmicd's log lines: syslog priority prefixes under journald, repeated messages folded.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "daemon_logger.hpp"

namespace {

// Captures what is written to file descriptor 2 while alive.
class StderrCapture {
 public:
  StderrCapture() : file_(std::tmpfile()), saved_(::dup(2)) { ::dup2(::fileno(file_), 2); }
  ~StderrCapture() {
    ::dup2(saved_, 2);
    ::close(saved_);
    std::fclose(file_);
  }
  std::string text() {
    std::fflush(stderr);
    std::rewind(file_);
    std::string out;
    char buffer[4096];
    std::size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, file_)) > 0) out.append(buffer, n);
    return out;
  }

 private:
  std::FILE* file_;
  int saved_;
};

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

TEST(DaemonLoggerTest, JournaldGetsPriorityPrefixes) {
  ::setenv("JOURNAL_STREAM", "8:1234", 1);
  StderrCapture capture;
  {
    cosmicd::DaemonLogger log(cosmic::LogLevel::debug);
    log.log(cosmic::LogLevel::error, "bus off");
    log.log(cosmic::LogLevel::warning, "degraded");
    log.log(cosmic::LogLevel::notice, "audit: bind");
    log.log(cosmic::LogLevel::info, "bound");
    log.log(cosmic::LogLevel::debug, "detail");
  }
  ::unsetenv("JOURNAL_STREAM");
  const std::string text = capture.text();
  EXPECT_NE(text.find("<3>bus off\n"), std::string::npos) << text;
  EXPECT_NE(text.find("<4>degraded\n"), std::string::npos);
  EXPECT_NE(text.find("<5>audit: bind\n"), std::string::npos);
  EXPECT_NE(text.find("<6>bound\n"), std::string::npos);
  EXPECT_NE(text.find("<7>detail\n"), std::string::npos);
}

TEST(DaemonLoggerTest, ThresholdFiltersLowerLevels) {
  StderrCapture capture;
  cosmicd::DaemonLogger log(cosmic::LogLevel::warning);
  log.log(cosmic::LogLevel::info, "chatter");
  log.log(cosmic::LogLevel::error, "problem");
  const std::string text = capture.text();
  EXPECT_EQ(text.find("chatter"), std::string::npos);
  EXPECT_NE(text.find("problem"), std::string::npos);
}

TEST(DaemonLoggerTest, RepeatedMessagesAreFolded) {
  StderrCapture capture;
  cosmicd::DaemonLogger log(cosmic::LogLevel::info, std::chrono::milliseconds(100));
  for (int i = 0; i < 50; ++i) log.log(cosmic::LogLevel::error, "segment can0: bus off");
  log.log(cosmic::LogLevel::error, "another message");
  std::this_thread::sleep_for(std::chrono::milliseconds(150));  // the folding window is time itself
  log.log(cosmic::LogLevel::error, "segment can0: bus off");
  const std::string text = capture.text();
  EXPECT_EQ(count(text, "segment can0: bus off"), 2u) << text;
  EXPECT_NE(text.find("segment can0: bus off (repeated 49 more times)"), std::string::npos) << text;
  EXPECT_EQ(count(text, "another message"), 1u);
}

}  // namespace
