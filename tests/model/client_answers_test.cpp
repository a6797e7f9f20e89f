// libcosmic-client against a fake gateway that answers badly (issue 22, item 7): every malformed
// control answer is an error code with a reason, never an abort or an exception crossing the C
// API, and an answer that never ends is cut off instead of read whole.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "cosmic/client.h"

namespace {

// Answers every connection with `answer` (sent in pieces), then closes it.
class FakeGateway {
 public:
  explicit FakeGateway(std::string answer) : answer_(std::move(answer)) {
    path_ = (std::filesystem::temp_directory_path() / ("cosmic-fake-" + std::to_string(::getpid()) + ".sock")).string();
    ::unlink(path_.c_str());
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, path_.c_str(), sizeof address.sun_path - 1);
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    EXPECT_EQ(::listen(fd_, 4), 0);
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeGateway() {
    ::shutdown(fd_, SHUT_RDWR);
    ::close(fd_);
    thread_.join();
    ::unlink(path_.c_str());
  }
  const std::string& path() const { return path_; }

 private:
  void serve() {
    for (;;) {
      const int client = ::accept(fd_, nullptr, nullptr);
      if (client < 0) return;
      char request[1024];
      (void)::recv(client, request, sizeof request, 0);
      for (std::size_t at = 0; at < answer_.size();) {
        const ssize_t n =
            ::send(client, answer_.data() + at, std::min<std::size_t>(65536, answer_.size() - at), MSG_NOSIGNAL);
        if (n <= 0) break;
        at += static_cast<std::size_t>(n);
      }
      ::close(client);
    }
  }
  std::string answer_;
  std::string path_;
  int fd_ = -1;
  std::thread thread_;
};

int check(const std::string& answer, std::string& verdict_text) {
  FakeGateway gateway(answer);
  char verdict[256] = {};
  const int rc = cosmic_check_channel(gateway.path().c_str(), "speed", verdict, sizeof verdict);
  verdict_text = verdict;
  return rc;
}

TEST(ClientAnswers, EveryMalformedAnswerIsAnErrorCode) {
  for (const char* answer : {"{\"ok\":true}\n", "{\"ok\":\"yes\",\"channel\":{\"verdict\":\"bound\"}}\n",
                             "{\"ok\":true,\"channel\":\"speed\"}\n", "{\"ok\":true,\"channel\":{\"verdict\":7}}\n",
                             "{\"ok\":false,\"error\":\"nope\"}\n", "{\"ok\":false,\"error\":{\"code\":5}}\n",
                             "{\"ok\":false}\n", "[1,2]\n", "null\n", "{\"ok\":true,\"channel\":{}}\n", "not json\n"}) {
    std::string verdict;
    EXPECT_EQ(check(answer, verdict), COSMIC_E_UNAVAILABLE) << answer;
    EXPECT_FALSE(verdict.empty()) << "no reason for " << answer;
  }
}

TEST(ClientAnswers, WellFormedAnswersStillWork) {
  std::string verdict;
  EXPECT_EQ(check("{\"ok\":true,\"channel\":{\"verdict\":\"degraded\"}}\n", verdict), COSMIC_OK);
  EXPECT_EQ(verdict, "degraded");
  EXPECT_EQ(check("{\"ok\":false,\"error\":{\"code\":\"rejected\",\"reasons\":[\"too slow\",3]}}\n", verdict),
            COSMIC_OK);
  EXPECT_EQ(verdict, "rejected (too slow)");
  EXPECT_EQ(check("{\"ok\":false,\"error\":{\"code\":\"not_found\"}}\n", verdict), COSMIC_OK);
  EXPECT_EQ(verdict, "not_found");
}

TEST(ClientAnswers, AnAnswerThatNeverEndsIsCutOff) {
  std::string verdict;
  EXPECT_EQ(check(std::string(20u << 20, 'x'), verdict), COSMIC_E_UNAVAILABLE);
  EXPECT_NE(verdict.find("longer than"), std::string::npos) << verdict;
}

}  // namespace
