#include "tools/brdfctl/commands/watch.h"

#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/json.h"
#include "tools/brdfctl/output/rounds_text.h"
#include "tools/brdfctl/output/session_text.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/rpc_error.h"
#include "tools/brdfctl/watch/eta_calibrator.h"
#include "tools/brdfctl/watch/progress_line.h"
#include "tools/brdfctl/watch/prompt_hook.h"

namespace brdf::ctl {
namespace {

bool Terminal(v1::SessionState s) {
  return s == v1::SESSION_STATE_COMPLETED || s == v1::SESSION_STATE_ABORTED ||
         s == v1::SESSION_STATE_FAILED;
}

class Watcher {
 public:
  Watcher(CommandContext& ctx, const WatchOptions& options)
      : ctx_(ctx), options_(options), notes_(ctx.json ? ctx.err : ctx.out) {}

  // The stream is read on its own thread into a queue, so that a question waiting for the
  // operator's answer never hides what the session does meanwhile (a pause, an abort, the prompt
  // answered elsewhere withdraw it).
  int Run() {
    v1::WatchSessionRequest request;
    request.set_session_id(options_.session_id);
    auto context = ctx_.client.StreamContext();
    auto reader = ctx_.client.control().WatchSession(context.get(), request);
    std::thread pump([&] {
      v1::SessionEvent event;
      while (reader->Read(&event)) {
        std::lock_guard<std::mutex> lock(queue_mu_);
        queue_.push_back(event);
        queue_cv_.notify_one();
      }
      std::lock_guard<std::mutex> lock(queue_mu_);
      stream_ended_ = true;
      queue_cv_.notify_one();
    });
    int exit_code = kExitOk;
    for (;;) {
      std::optional<v1::SessionEvent> event;
      bool ended = false;
      {
        std::unique_lock<std::mutex> lock(queue_mu_);
        queue_cv_.wait_for(lock, std::chrono::milliseconds(question_ ? 50 : 500),
                           [this] { return !queue_.empty() || stream_ended_; });
        if (!queue_.empty()) {
          event = std::move(queue_.front());
          queue_.pop_front();
        } else {
          ended = stream_ended_;
        }
      }
      if (event) exit_code = Handle(*event);
      if (exit_code == kExitOk && question_) exit_code = PollAnswer();
      if (exit_code != kExitOk || ended) break;
    }
    if (exit_code != kExitOk) context->TryCancel();
    pump.join();
    const grpc::Status status = reader->Finish();
    ClearBar();
    if (exit_code != kExitOk) return exit_code;
    if (!status.ok()) {
      return ReportRpcError(ctx_.err, status, "WatchSession", ctx_.client.options().address);
    }
    return Finished();
  }

 private:
  // Returns non-zero to stop watching with that exit status.
  int Handle(const v1::SessionEvent& event) {
    if (ctx_.json) PrintJsonLine(ctx_.out, event);
    switch (event.event_case()) {
      case v1::SessionEvent::kSnapshot: {
        const v1::Session& s = event.snapshot();
        state_ = s.state();
        view_.state = StateName(s.state());
        view_.done_steps = s.progress().done_steps();
        view_.total_steps = s.progress().total_steps();
        view_.eta_s = s.eta_s() > 0 ? s.eta_s() : -1;
        view_.quality_code = s.last_quality_code();
        Note("watching session " + s.session_id() + " \"" + s.name() + "\": " + view_.state +
             (s.state_reason().empty() ? "" : " (" + s.state_reason() + ")") + ", " +
             ProgressText(s.progress()));
        if (s.plan().has_adaptive()) OnAdaptive(s);
        if (s.has_pending_prompt()) return OnPrompt(s.pending_prompt());
        if (s.state() == v1::SESSION_STATE_PAUSED) {
          const int paused = OnPaused(s.state_reason());
          if (paused != kExitOk) return paused;
        }
        break;
      }
      case v1::SessionEvent::kStateChanged: {
        const v1::StateChange& c = event.state_changed();
        state_ = c.to();
        view_.state = StateName(c.to());
        if (!c.reason().empty()) end_reason_ = c.reason();
        if (c.to() != v1::SESSION_STATE_RUNNING) eta_.Interrupt();
        if (c.to() == v1::SESSION_STATE_QUEUED) view_.eta_s = -1;  // no running ETA while queued
        if (c.from() == v1::SESSION_STATE_AWAITING_OPERATOR) WithdrawQuestion(c);
        // Into and out of a prompt we answered: the prompt and "confirmed" lines already say it.
        const bool prompt_traffic = c.to() == v1::SESSION_STATE_AWAITING_OPERATOR ||
                                    (c.from() == v1::SESSION_STATE_AWAITING_OPERATOR &&
                                     c.to() == v1::SESSION_STATE_RUNNING);
        if (!prompt_traffic) {
          Note("state: " + StateName(c.from()) + " → " + StateName(c.to()) +
               (c.reason().empty() ? "" : " (" + c.reason() + ")"));
        }
        if (c.to() == v1::SESSION_STATE_PAUSED) {
          const int paused = OnPaused(c.reason());
          if (paused != kExitOk) return paused;
        }
        break;
      }
      case v1::SessionEvent::kPrompt:
        return OnPrompt(event.prompt());
      case v1::SessionEvent::kStepCompleted:
        OnStep(event.step_completed());
        break;
      case v1::SessionEvent::kFault:
        Note(FaultText(event.fault()));
        break;
      case v1::SessionEvent::kAdaptiveRound:
        for (const std::string& line : AdaptiveRoundLines(event.adaptive_round(), adaptive_)) {
          Note(line);
        }
        break;
      case v1::SessionEvent::kAdaptiveStop:
        for (const std::string& line : AdaptiveStopLines(event.adaptive_stop(), adaptive_)) {
          Note(line);
        }
        break;
      default:
        break;
    }
    DrawBar();
    return kExitOk;
  }

  // An adaptive session watched: its target and budgets, and the rounds stored before the watch
  // began (the uncertainty left falling, then the round being measured). Best effort: a daemon
  // that cannot list them leaves the rounds to the events.
  void OnAdaptive(const v1::Session& s) {
    adaptive_ = s.plan().adaptive();
    if (ctx_.json) return;
    Note(AdaptiveGoalText(adaptive_));
    v1::ListAdaptiveRoundsRequest request;
    request.set_session_id(s.session_id());
    v1::ListAdaptiveRoundsResponse reply;
    if (!ctx_.client.control()
             .ListAdaptiveRounds(ctx_.client.UnaryContext().get(), request, &reply)
             .ok() ||
        reply.rounds().empty()) {
      return;
    }
    const std::vector<v1::AdaptiveRound> rounds(reply.rounds().begin(), reply.rounds().end());
    Note(RoundsSoFarText(rounds));
    for (const std::string& line : AdaptiveRoundLines(rounds.back(), adaptive_)) {
      Note(line);
    }
  }

  void OnStep(const v1::StepCompletion& step) {
    view_.done_steps = step.progress().done_steps();
    view_.total_steps = step.progress().total_steps();
    const double now_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    eta_.OnStep(step.kind(), step.eta_s(), now_s);
    view_.eta_s = eta_.Eta(step.eta_s());
    if (step.quality_code() >= 0) view_.quality_code = step.quality_code();
    integration_note_.clear();
    if (step.reading_id() > 0 && !ctx_.json) FetchPose(step.reading_id());
    if (options_.progress_bar && !integration_note_.empty()) {
      // Worth a line of its own even under the bar: the reading is not what the plan asked for.
      Note("reading " + std::to_string(step.reading_id()) +
           ": integration changed by the meter: " + integration_note_);
    }
    if (options_.progress_bar || ctx_.json) return;
    std::string line = "[" + std::to_string(view_.done_steps) + "/" +
                       std::to_string(view_.total_steps) + "] step " +
                       std::to_string(step.step_index()) + " " + StepKindName(step.kind());
    if (step.reading_id() > 0) {
      line += ": reading " + std::to_string(step.reading_id()) + ", quality " +
              std::to_string(step.quality_code());
      if (step.flagged()) line += " (flagged)";
      if (view_.pose) line += ", " + PoseText(*view_.pose);
      if (!integration_note_.empty()) {
        line += ", integration changed by the meter: " + integration_note_;
      }
    }
    line += ", ETA " + Duration(view_.eta_s);
    ctx_.out << line << std::endl;
  }

  // The pose (and integration note) of a reading that just landed: its id is known, so ask for the
  // readings after id − 1 (without follow, the stream sends what is stored and closes). Best
  // effort: the display only.
  void FetchPose(std::int64_t reading_id) {
    v1::StreamReadingsRequest request;
    request.set_session_id(options_.session_id);
    request.set_after_id(reading_id - 1);
    auto context = ctx_.client.UnaryContext();
    auto reader = ctx_.client.data().StreamReadings(context.get(), request);
    v1::Reading reading;
    if (reader->Read(&reading) && reading.id() == reading_id) {
      view_.pose = reading.pose();
      integration_note_ = reading.integration_note();
    }
    context->TryCancel();
    reader->Finish();
  }

  int OnPrompt(const v1::Prompt& prompt) {
    const int step = prompt.step_index();
    if (answered_.count(step) > 0 || declined_.count(step) > 0) return kExitOk;
    if (question_ && question_->step_index() == step) return kExitOk;
    ClearBar();
    std::ostringstream text;
    PrintPrompt(text, prompt);
    notes_ << text.str();
    open_prompt_ = step;
    if (options_.auto_confirm) return Confirm(prompt);
    if (options_.ask) {
      // Asked, not waited for: the answer is read between events (PollAnswer).
      notes_ << "Done? Confirm the prompt [y/N]: " << std::flush;
      question_ = prompt;
      answer_.clear();
      return kExitOk;
    }
    if (!options_.on_prompt.empty()) {
      // Not asking and not confirming: the hook is not run, and saying so beats silence.
      notes_ << "  --on-prompt runs only before a confirmation: add --auto-confirm (or --ask to "
                "answer y/N on standard input)"
             << std::endl;
    }
    Decline(step);
    return kExitOk;
  }

  // Reads what the operator typed so far (without blocking); a full line answers the question.
  int PollAnswer() {
    pollfd in{STDIN_FILENO, POLLIN, 0};
    while (question_ && ::poll(&in, 1, 0) > 0) {
      char buffer[256];
      const ssize_t n = ::read(STDIN_FILENO, buffer, sizeof buffer);
      const bool eof = n <= 0;
      if (!eof) answer_.append(buffer, static_cast<size_t>(n));
      const size_t newline = answer_.find('\n');
      if (!eof && newline == std::string::npos) continue;
      const std::string line = answer_.substr(0, newline);
      const v1::Prompt prompt = *question_;
      question_.reset();
      answer_.clear();
      if (line == "y" || line == "Y" || line == "yes") return Confirm(prompt);
      Decline(prompt.step_index());
      if (eof) break;
    }
    return kExitOk;
  }

  // The session left awaiting_operator (paused, aborted, answered elsewhere): an open question
  // about its prompt is withdrawn, and neither answered nor its --on-prompt hook run.
  void WithdrawQuestion(const v1::StateChange& change) {
    if (!open_prompt_) return;
    const int step = *open_prompt_;
    open_prompt_.reset();
    if (answered_.count(step) > 0) return;
    const bool asked = question_.has_value();
    question_.reset();
    answer_.clear();
    if (asked) notes_ << "\n";
    const std::string why = change.to() == v1::SESSION_STATE_RUNNING
                                ? "answered elsewhere"
                                : "the session is now " + StateName(change.to()) +
                                      (change.reason().empty() ? "" : " (" + change.reason() + ")");
    Note("  prompt at step " + std::to_string(step) + " withdrawn: " + why +
         (asked ? "; not confirmed" : "") +
         (change.to() == v1::SESSION_STATE_RUNNING ? "" : "; it comes again on resume"));
    declined_.erase(step);  // a prompt that is due again is shown again
  }

  void Decline(int step) {
    declined_.insert(step);
    notes_ << "  not confirmed; when done: brdfctl answer " << options_.session_id << " " << step
           << std::endl;
    DrawBar();
  }

  int Confirm(const v1::Prompt& prompt) {
    const int step = prompt.step_index();
    if (!options_.on_prompt.empty()) {
      const Status hook = RunPromptHook(options_.on_prompt, options_.session_id, prompt);
      if (!hook.ok()) {
        ctx_.err << "brdfctl: " << hook.message() << "\n";
        return kExitFailure;
      }
    }
    v1::AnswerPromptRequest request;
    request.set_session_id(options_.session_id);
    request.set_step_index(step);
    request.set_note(options_.auto_confirm ? "confirmed by brdfctl watch --auto-confirm"
                                           : "confirmed in brdfctl watch");
    v1::AnswerPromptResponse reply;
    const grpc::Status status =
        ctx_.client.control().AnswerPrompt(ctx_.client.UnaryContext().get(), request, &reply);
    if (status.error_code() == grpc::StatusCode::FAILED_PRECONDITION) {
      // Paused, aborted or answered elsewhere meanwhile; a prompt that is still due comes again.
      notes_ << "  prompt at step " << step << " is no longer pending: " << status.error_message()
             << std::endl;
      DrawBar();
      return kExitOk;
    }
    if (!status.ok()) {
      return ReportRpcError(ctx_.err, status, "AnswerPrompt", ctx_.client.options().address);
    }
    answered_.insert(step);
    notes_ << "  confirmed (step " << step << ")" << std::endl;
    DrawBar();
    return kExitOk;
  }

  int OnPaused(const std::string& reason) {
    if (!options_.exit_on_pause) return kExitOk;
    ClearBar();
    ctx_.err << "brdfctl: session " << options_.session_id << " paused"
             << (reason.empty() ? "" : ": " + reason) << "\n  resume it: brdfctl resume "
             << options_.session_id << "\n";
    return kExitNoResult;
  }

  int Finished() {
    if (state_ == v1::SESSION_STATE_COMPLETED) {
      Note("session " + options_.session_id + " completed: " + std::to_string(view_.done_steps) +
           "/" + std::to_string(view_.total_steps) + " steps");
      return kExitOk;
    }
    if (Terminal(state_)) {
      ctx_.err << "brdfctl: session " << options_.session_id << " ended " << StateName(state_)
               << (end_reason_.empty() ? "" : ": " + end_reason_) << "\n";
      return kExitNoResult;
    }
    ctx_.err << "brdfctl: the watch stream of session " << options_.session_id
             << " ended while the session was " << StateName(state_)
             << "; the daemon may be shutting down (brdfctl get " << options_.session_id
             << " shows where it is)\n";
    return kExitFailure;
  }

  // A line above the progress bar (or on stderr with --json).
  void Note(const std::string& line) {
    ClearBar();
    notes_ << line << std::endl;
  }

  void DrawBar() {
    if (!options_.progress_bar || ctx_.json) return;
    ctx_.out << "\r" << RenderProgressLine(view_, options_.width - 1) << "\x1b[K" << std::flush;
    bar_shown_ = true;
  }

  void ClearBar() {
    if (!bar_shown_) return;
    ctx_.out << "\r\x1b[K" << std::flush;
    bar_shown_ = false;
  }

  CommandContext& ctx_;
  const WatchOptions& options_;
  std::ostream& notes_;
  ProgressView view_;
  EtaCalibrator eta_;
  std::string integration_note_;  // of the reading of the step being shown
  v1::SessionState state_ = v1::SESSION_STATE_UNSPECIFIED;
  std::string end_reason_;
  v1::Adaptive adaptive_;  // an adaptive session's plan (its target and budgets)
  std::set<int> answered_;
  std::set<int> declined_;
  std::optional<int> open_prompt_;      // the prompt shown and not answered by us
  std::optional<v1::Prompt> question_;  // asked [y/N], the answer not read yet
  std::string answer_;                  // what the operator typed so far
  std::mutex queue_mu_;
  std::condition_variable queue_cv_;
  std::deque<v1::SessionEvent> queue_;  // read from the stream, not handled yet
  bool stream_ended_ = false;
  bool bar_shown_ = false;
};

}  // namespace

int RunWatch(CommandContext& ctx, const WatchOptions& options) {
  return Watcher(ctx, options).Run();
}

namespace {

int TerminalWidth() {
  winsize ws{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
  if (const char* columns = std::getenv("COLUMNS")) {
    const int n = std::atoi(columns);
    if (n > 0) return n;
  }
  return 80;
}

Runner AddWatchOptions(CLI::App& cmd) {
  struct Args {
    WatchOptions options;
    bool force_ask = false;
    bool no_progress = false;
  };
  auto args = std::make_shared<Args>();
  AddSessionId(cmd, args->options.session_id);
  cmd.add_flag("--auto-confirm", args->options.auto_confirm, "confirm every prompt without asking");
  cmd.add_option("--on-prompt", args->options.on_prompt,
                 "shell command run before confirming a prompt; sees BRDF_PROMPT_KIND, "
                 "BRDF_PROMPT_STEP, BRDF_PROMPT_TEXT, BRDF_SESSION_ID, BRDF_PROMPT_DELTA …");
  cmd.add_flag("--ask", args->force_ask,
               "ask y/N for each prompt on standard input even when it is not a terminal");
  cmd.add_flag("--no-progress", args->no_progress, "plain lines even on a terminal");
  cmd.add_flag("--exit-on-pause", args->options.exit_on_pause,
               "stop watching (exit 4) when the session pauses, e.g. after a device fault");
  return OnDaemon([args](CommandContext& ctx) {
    WatchOptions options = args->options;
    const bool tty_out = isatty(STDOUT_FILENO) != 0;
    options.progress_bar = tty_out && !ctx.json && !args->no_progress;
    options.ask =
        (args->force_ask || (tty_out && isatty(STDIN_FILENO) != 0)) && !options.auto_confirm;
    options.width = TerminalWidth();
    return RunWatch(ctx, options);
  });
}

}  // namespace

void RegisterWatchCommand(CommandRegistry& registry) {
  registry.Add({"watch", "follow a session live until it ends, confirming operator prompts", "",
                AddWatchOptions});
}

}  // namespace brdf::ctl
