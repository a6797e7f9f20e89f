// The metrics endpoint's HTTP handling without a network (issue 22, item 3): the request head's
// byte budget and the fields it drops, what cpp-httplib answers behind it, and which connection
// the registry evicts at its cap. The attacks over real sockets are
// tests/integration/metrics/hostile_http_test.sh.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <future>
#include <string>
#include <thread>

#include "metrics_http_connections.hpp"
#include "metrics_http_head.hpp"
#include "metrics_http_server.hpp"

namespace cosmicd {
namespace {

const std::string kDocument = "# HELP cosmic_up 1 while cosmicd runs\n# TYPE cosmic_up gauge\ncosmic_up 1\n";

std::string status_of(const std::string& response) { return response.substr(0, response.find("\r\n")); }
std::string body_of(const std::string& response) {
  const auto end = response.find("\r\n\r\n");
  return end == std::string::npos ? std::string() : response.substr(end + 4);
}

class MetricsHttp : public ::testing::Test {
 protected:
  MetricsHttp() : server(HttpLimits{}, nullptr, nullptr) {
    server.serve_metrics([](ExpositionFormat) { return std::optional<std::string>(kDocument); });
  }
  MetricsHttpServer server;
};

TEST(RequestHead, EndsAtTheFirstBlankLineAcrossPieces) {
  RequestHead head(4096);
  const std::string bytes = "GET /metrics HTTP/1.1\r\nHost: x\r\n\r\nGET / HTTP/1.1\r\n";
  std::size_t used = 0;
  for (char c : bytes) used += head.feed(std::string_view(&c, 1));
  EXPECT_EQ(head.state(), RequestHead::State::complete);
  EXPECT_EQ(head.text(), "GET /metrics HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(used, head.size());
}

TEST(RequestHead, MoreThanTheBudgetIsTooLarge) {
  RequestHead head(4096);
  const std::string line = "X-Filler: " + std::string(80, 'f') + "\r\n";
  std::string bytes = "GET /metrics HTTP/1.1\r\n";
  while (bytes.size() < 5000) bytes += line;
  EXPECT_EQ(head.feed(bytes), 4096u);
  EXPECT_EQ(head.state(), RequestHead::State::too_large);
  EXPECT_EQ(head.feed("\r\n\r\n"), 0u);

  RequestHead exact(64);  // a head of exactly the budget, its blank line included, is complete
  std::string fits = "GET / HTTP/1.1\r\nX: ";
  fits += std::string(64 - fits.size() - 4, 'a') + "\r\n\r\n";
  exact.feed(fits);
  EXPECT_EQ(exact.state(), RequestHead::State::complete);
}

TEST(RequestHead, ForwardsEverythingButRangeFields) {
  RequestHead head(4096);
  head.feed(
      "GET /metrics HTTP/1.1\r\nRANGE: bytes=0-\r\nAccept: */*\r\nif-range: x\r\nRange : bytes=0-\r\n"
      "X-Range: kept\r\n\r\n");
  EXPECT_EQ(head.forwarded(), "GET /metrics HTTP/1.1\r\nAccept: */*\r\nX-Range: kept\r\n\r\n");
  EXPECT_FALSE(ignored_field("Rangefinder: 1"));
  EXPECT_TRUE(ignored_field("range:"));
}

// cpp-httplib parses Range before the setup_request hook runs, and answers a malformed one 416
// before it: the field must go before cpp-httplib sees the head.
TEST_F(MetricsHttp, RangeIsNeverHonoured) {
  std::string ranges = "0-";
  for (int i = 0; i < 1000; ++i) ranges += ",0-";
  for (const std::string& range : {ranges, std::string("0-10"), std::string("abc"), std::string("5-1")}) {
    const std::string response = server.answer("GET /metrics HTTP/1.1\r\nRange: bytes=" + range + "\r\n\r\n");
    EXPECT_EQ(status_of(response), "HTTP/1.1 200 OK") << range.substr(0, 20);
    EXPECT_EQ(body_of(response), kDocument);
  }
}

TEST_F(MetricsHttp, HeadOverTheLimitIs431) {
  std::string request = "GET /metrics HTTP/1.1\r\n";
  while (request.size() < 8192) request += "X-Filler: " + std::string(80, 'f') + "\r\n";
  request += "\r\n";
  EXPECT_EQ(status_of(server.answer(request)), "HTTP/1.1 431 Request Header Fields Too Large");
}

TEST_F(MetricsHttp, AnswersScrapesAndRefusesTheRest) {
  EXPECT_EQ(body_of(server.answer("GET /metrics HTTP/1.1\r\nHost: x\r\n\r\n")), kDocument);
  EXPECT_EQ(status_of(server.answer("GET /nothing HTTP/1.1\r\n\r\n")), "HTTP/1.1 404 Not Found");
  EXPECT_EQ(server.answer("GET /metrics HTTP/1.1\r\nHost: x\r\n"), "");  // incomplete: waits
}

// Sockets that report a shutdown(2) as readable end-of-stream on the peer's side.
struct Pair {
  Pair() { EXPECT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fd), 0); }
  ~Pair() {
    ::close(fd[0]);
    ::close(fd[1]);
  }
  bool shut_down() const {
    char c;
    return ::recv(fd[1], &c, 1, MSG_DONTWAIT) == 0;
  }
  int fd[2];
};

// The order of set() calls is the order of the states' start; the pauses only keep the clock's
// readings apart.
void next_tick() { std::this_thread::sleep_for(std::chrono::milliseconds(2)); }

// At the cap, the next acquire_slot() shuts `expected` down; once its thread has given the slot
// back, the new connection has it. False when `expected` was not shut down within 10 s.
bool next_slot_evicts(ConnectionRegistry& registry, const Pair& expected) {
  auto next = std::async(std::launch::async, [&] { return registry.acquire_slot(); });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!expected.shut_down()) {
    if (std::chrono::steady_clock::now() > deadline) {
      registry.stop();  // lets the waiting acquire_slot() return
      next.get();
      return false;
    }
    std::this_thread::yield();
  }
  registry.remove(expected.fd[0]);
  registry.release_slot();
  return next.get();
}

TEST(ConnectionRegistry, AtTheCapEvictsTheLongestWaitingNeverTheServed) {
  ConnectionRegistry registry(4);
  Pair serving, slow_head, idle, scraper, newcomer;
  for (const Pair* p : {&serving, &slow_head, &idle, &scraper}) {
    ASSERT_TRUE(registry.acquire_slot());
    ASSERT_TRUE(registry.add(p->fd[0]));
  }
  registry.set(serving.fd[0], ConnectionState::serving);
  next_tick();
  registry.set(scraper.fd[0], ConnectionState::idle);
  ASSERT_EQ(::send(scraper.fd[1], "G", 1, 0), 1);  // its request is in flight
  next_tick();
  registry.set(slow_head.fd[0], ConnectionState::reading);
  next_tick();
  registry.set(idle.fd[0], ConnectionState::idle);

  // The head that began longest ago; not the scraper with input waiting, although it is older.
  ASSERT_TRUE(next_slot_evicts(registry, slow_head));
  ASSERT_TRUE(registry.add(newcomer.fd[0]));
  registry.set(newcomer.fd[0], ConnectionState::serving);

  // Then the idle one; the scraper only when nothing else is left; never one being served.
  ASSERT_TRUE(next_slot_evicts(registry, idle));
  ASSERT_TRUE(next_slot_evicts(registry, scraper));
  EXPECT_FALSE(serving.shut_down());
  EXPECT_FALSE(newcomer.shut_down());
  EXPECT_EQ(registry.evictions(), 3u);

  registry.stop();
  EXPECT_TRUE(serving.shut_down());
  EXPECT_FALSE(registry.acquire_slot());
  EXPECT_FALSE(registry.add(42));
}

}  // namespace
}  // namespace cosmicd
