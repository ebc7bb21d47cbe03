#include "daemon/config/startup.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace brdf::daemon {

sigset_t BlockStopSignals() {
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);
  return stop_signals;
}

void StartLogging(const std::string& program) {
  auto logger = spdlog::stderr_color_mt(program);
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");
}

Result<Config> LoadConfigAndLogLevel(const std::string& path, const std::string& log_level) {
  BRDF_ASSIGN_OR_RETURN(Config loaded, LoadConfig(path));
  spdlog::set_level(spdlog::level::from_str(log_level.empty() ? loaded.log.level : log_level));
  return loaded;
}

}  // namespace brdf::daemon
