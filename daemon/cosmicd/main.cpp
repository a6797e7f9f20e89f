// cosmicd: the cosmic-gateway daemon. Thin main: configuration, gateway (adapters + router),
// control socket, signals, service manager notifications.
#include <CLI/CLI.hpp>
#include <csignal>
#include <iostream>
#include <random>
#include <sys/signalfd.h>
#include <unistd.h>

#include "adapter_factory.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/control_protocol.hpp"
#include "cosmic/control_server.hpp"
#include "cosmic/gateway.hpp"
#include "daemon_logger.hpp"

namespace {

constexpr int kExitConfigError = 2;
constexpr int kExitStartFailure = 1;

std::uint64_t random_gateway_id() {
  std::random_device device;
  std::uint64_t id = 0;
  while (id == 0) id = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  return id;
}

struct Options {
  std::string config = "/etc/cosmic/cosmicd.yaml";
  std::string socket;  // overrides gateway.control_socket
  std::string log_level = "info";
};

cosmic::LogLevel parse_level(const std::string& text) {
  if (text == "debug") return cosmic::LogLevel::debug;
  if (text == "notice") return cosmic::LogLevel::notice;
  if (text == "warning") return cosmic::LogLevel::warning;
  if (text == "error") return cosmic::LogLevel::error;
  return cosmic::LogLevel::info;
}

void log_bind_result(cosmic::Logger& log, const cosmic::BindResult& result) {
  for (const auto& channel : result.channels) {
    std::string line = "channel " + channel.name + " (" + cosmic::to_string(channel.cls) + "): " + cosmic::to_string(channel.verdict);
    for (const auto& reason : channel.reasons) line += "; " + reason;
    log.log(channel.verdict == cosmic::Verdict::bound ? cosmic::LogLevel::info : cosmic::LogLevel::warning, line);
  }
}

// Blocks the termination and reload signals in every thread and returns a signalfd for them.
int signal_descriptor() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  return signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cosmicd: event-channel gateway between CAN, DDS and LCM"};
  Options options;
  app.add_option("-c,--config", options.config, "Configuration file")->capture_default_str();
  app.add_option("-s,--socket", options.socket, "Control socket path (overrides gateway.control_socket)");
  app.add_option("-l,--log-level", options.log_level, "debug, info, notice, warning or error")
      ->check(CLI::IsMember({"debug", "info", "notice", "warning", "error"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const int signal_fd = signal_descriptor();
  cosmicd::DaemonLogger log(parse_level(options.log_level));
  const auto loaded = cosmic::load_config_file(options.config);
  if (!loaded.ok()) {
    for (const auto& error : loaded.errors) log.log(cosmic::LogLevel::error, error.to_string());
    return kExitConfigError;
  }
  cosmic::Config config = loaded.config;
  const std::string socket_path = options.socket.empty() ? config.gateway.control_socket : options.socket;

  cosmic::Gateway gateway(cosmicd::make_adapter, log, random_gateway_id());
  const auto started = gateway.start(config);
  if (!started.applied) {
    log.log(cosmic::LogLevel::error, started.error);
    return kExitStartFailure;
  }
  log_bind_result(log, started);

  auto reload_source = [&] { return cosmic::load_config_file(options.config); };
  cosmic::ControlProtocol protocol(gateway, reload_source, cosmic::AccessPolicy{}, log);
  cosmic::ControlServerOptions server_options;
  server_options.path = socket_path;
  cosmic::ControlServer server(server_options,
                               [&](std::string_view line, const cosmic::PeerCredentials& peer) { return protocol.handle(line, peer); });
  bool running = true;
  server.watch(signal_fd, [&] {
    signalfd_siginfo info{};
    while (read(signal_fd, &info, sizeof info) == sizeof info) {
      if (info.ssi_signo == SIGHUP) {
        log.log(cosmic::LogLevel::notice, "SIGHUP: reloading " + options.config);
        const auto reloaded = cosmic::load_config_file(options.config);
        if (!reloaded.ok()) {
          for (const auto& error : reloaded.errors) log.log(cosmic::LogLevel::error, error.to_string());
          log.log(cosmic::LogLevel::error, "reload refused; the running configuration is unchanged");
        } else {
          log_bind_result(log, gateway.reload(reloaded.config));
        }
      } else {
        log.log(cosmic::LogLevel::notice, "signal " + std::to_string(info.ssi_signo) + ": shutting down");
        running = false;
      }
    }
  });
  if (const auto opened = server.open(); !opened.ok) {
    log.log(cosmic::LogLevel::error, "control socket: " + opened.error);
    gateway.stop();
    return kExitStartFailure;
  }
  log.log(cosmic::LogLevel::notice, "cosmicd " + config.gateway.name + " running; control socket " + socket_path);
  auto last_health = std::chrono::steady_clock::now();
  while (running) {
    server.run_for(std::chrono::milliseconds(200));
    if (std::chrono::steady_clock::now() - last_health >= std::chrono::milliseconds(500)) {
      gateway.refresh_health();
      last_health = std::chrono::steady_clock::now();
    }
  }
  server.close_all();
  gateway.stop();
  log.log(cosmic::LogLevel::notice, "cosmicd stopped");
  return 0;
}
