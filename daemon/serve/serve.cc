#include "daemon/serve/serve.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <thread>
#include <utility>

#ifdef BRDF_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace brdf::daemon {
namespace {

constexpr int kExitFailure = 1;

void Notify([[maybe_unused]] const std::string& state) {
#ifdef BRDF_HAVE_SYSTEMD
  sd_notify(0, state.c_str());
#endif
}

}  // namespace

Result<std::unique_ptr<Serving>> Serving::Start(const Program& program, const Config& config,
                                                const BackEnd& back_end,
                                                const Authenticator& auth) {
  std::unique_ptr<Serving> serving(new Serving());
  serving->program_ = program;
  BackEnd served = back_end;
  served.exports = ExportInterpolantsOptionsFrom(config);
  Result<std::unique_ptr<Server>> server = Server::Start(config.server, served, auth);
  if (!server.ok()) {
    spdlog::critical("{}", server.status().ToString());
    return server.status();
  }
  serving->server_ = std::move(*server);
  const Server& s = *serving->server_;
  spdlog::info("serving on {} ({})", s.address(), s.tls() ? "TLS" : "plaintext");
  if (!config.web.listen.empty()) {
    Result<std::unique_ptr<WebGateway>> web =
        WebGateway::Start(config.web, config.server.tls, DefaultWebRoot(config.web),
                          serving->server_->InProcessChannel(), auth, program.name);
    if (!web.ok()) {
      spdlog::critical("{}", web.status().ToString());
      serving->server_->Shutdown(std::chrono::seconds(1));
      return web.status();
    }
    serving->web_ = std::move(*web);
    std::printf("%s %s on %s\n", program.name.c_str(), program.web_name.c_str(),
                serving->web_->url().c_str());
  }
  std::printf("%s listening on %s\n", program.name.c_str(), s.address().c_str());
  std::fflush(stdout);
  Notify("READY=1\nSTATUS=serving on " + s.address());
  return serving;
}

Serving::~Serving() {
  Stop();
}

void Serving::Stop() {
  if (web_) web_->Stop();
  if (server_) server_->Shutdown(std::chrono::seconds(2));
}

void Serving::ServeUntilStopped(const sigset_t& stop_signals,
                                const std::function<void()>& stop_back_end) {
  int signal_number = 0;
  while (signal_number <= 0) signal_number = sigwaitinfo(&stop_signals, nullptr);
  spdlog::info("{}: {}", signal_number == SIGINT ? "SIGINT" : "SIGTERM", program_.stopping);
  Notify("STOPPING=1");

  std::atomic<bool> done{false};
  std::thread stopper([&] {
    stop_back_end();
    Stop();
    done = true;
  });
  const timespec poll{0, 100 * 1000 * 1000};
  while (!done) {
    if (sigtimedwait(&stop_signals, nullptr, &poll) > 0) {
      spdlog::warn("second stop signal: exiting now ({})", program_.lost);
      std::fflush(nullptr);
      std::_Exit(kExitFailure);
    }
  }
  stopper.join();
}

}  // namespace brdf::daemon
