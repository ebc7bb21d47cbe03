#include "tools/brdfctl/watch/prompt_hook.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "tools/brdfctl/output/text_format.h"

extern char** environ;

namespace brdf::ctl {

std::vector<std::pair<std::string, std::string>> PromptEnvironment(const std::string& session_id,
                                                                   const v1::Prompt& prompt) {
  std::vector<std::pair<std::string, std::string>> env = {
      {"BRDF_SESSION_ID", session_id},
      {"BRDF_PROMPT_STEP", std::to_string(prompt.step_index())},
      {"BRDF_PROMPT_KIND", PromptKindName(prompt.kind())},
      {"BRDF_PROMPT_TEXT", prompt.text()},
      {"BRDF_PROMPT_ALPHA", Num(prompt.pose().alpha(), 10)},
      {"BRDF_PROMPT_BETA", Num(prompt.pose().beta(), 10)},
      {"BRDF_PROMPT_GAMMA", Num(prompt.pose().gamma(), 10)},
      {"BRDF_PROMPT_DELTA", Num(prompt.pose().delta(), 10)},
  };
  if (prompt.has_target()) {
    const v1::Directions& t = prompt.target();
    env.insert(env.end(), {{"BRDF_PROMPT_THETA_I", Num(t.theta_i(), 10)},
                           {"BRDF_PROMPT_PHI_I", Num(t.phi_i(), 10)},
                           {"BRDF_PROMPT_THETA_O", Num(t.theta_o(), 10)},
                           {"BRDF_PROMPT_PHI_O", Num(t.phi_o(), 10)}});
  }
  return env;
}

Status RunPromptHook(const std::string& command, const std::string& session_id,
                     const v1::Prompt& prompt) {
  // Everything the child needs is built before fork(): after it, only async-signal-safe calls.
  std::vector<std::string> env_strings;
  const auto extra = PromptEnvironment(session_id, prompt);
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    bool replaced = false;
    for (const auto& [name, value] : extra) {
      replaced |= entry.compare(0, name.size() + 1, name + "=") == 0;
    }
    if (!replaced) env_strings.push_back(entry);
  }
  for (const auto& [name, value] : extra) env_strings.push_back(name + "=" + value);
  std::vector<char*> envp;
  for (std::string& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::string shell = "/bin/sh";
  std::string dash_c = "-c";
  std::string cmd = command;
  char* argv[] = {shell.data(), dash_c.data(), cmd.data(), nullptr};

  const pid_t pid = fork();
  if (pid < 0) {
    return IoError("--on-prompt: cannot start \"" + command + "\": " + std::strerror(errno));
  }
  if (pid == 0) {
    dup2(STDERR_FILENO, STDOUT_FILENO);
    execve(argv[0], argv, envp.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      return IoError("--on-prompt: waiting for \"" + command + "\": " + std::strerror(errno));
    }
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return Status::Ok();
  const std::string how = WIFEXITED(status)
                              ? "exited with status " + std::to_string(WEXITSTATUS(status))
                              : "was killed by signal " + std::to_string(WTERMSIG(status));
  return FailedPrecondition("--on-prompt command \"" + command + "\" " + how +
                            " for the prompt at step " + std::to_string(prompt.step_index()) +
                            " (" + PromptKindName(prompt.kind()) +
                            "); the prompt is still pending: do the action and run `brdfctl "
                            "answer " +
                            session_id + " " + std::to_string(prompt.step_index()) + "`");
}

}  // namespace brdf::ctl
