#include "tools/brdfctl/output/session_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/plan/rig_description.h"
#include "core/spectrum.h"
#include "tools/brdfctl/output/text_format.h"

namespace brdf::ctl {

std::string ProgressText(const v1::Progress& p) {
  std::string out = std::to_string(p.done_steps()) + "/" + std::to_string(p.total_steps()) +
                    " steps, " + std::to_string(p.done_samples()) + "/" +
                    std::to_string(p.total_samples()) + " sample readings";
  if (p.total_steps() > 0) {
    out += " (" + std::to_string(100 * p.done_steps() / p.total_steps()) + "%)";
  }
  return out;
}

std::string GridText(const v1::WavelengthGrid& g) {
  return brdf::GridText(WavelengthGrid{g.start_nm(), g.step_nm(), g.count()});
}

std::string SessionLine(const v1::Session& s) {
  std::string out = s.session_id() + "  " + StateName(s.state()) + "  " +
                    std::to_string(s.progress().done_steps()) + "/" +
                    std::to_string(s.progress().total_steps()) + " steps";
  if (s.eta_s() > 0) out += "  ETA " + Duration(s.eta_s());
  out += "  " + s.name();
  if (!s.rig().empty()) out += "  (rig " + s.rig() + ")";
  if (s.has_grid()) out += "  " + std::to_string(s.grid().count()) + " bands";
  return out;
}

double RigSeconds(const v1::PlanSummary& summary) {
  const double actions_s =
      summary.operator_interventions() * plan::RigDescription{}.operator_action_s;
  return std::max(0.0, summary.estimated_duration_s() - actions_s);
}

std::string PlanSummaryText(const v1::PlanSummary& summary, double time_scale, double real_rig_s) {
  std::string out = std::to_string(summary.step_count()) +
                    " steps: " + std::to_string(summary.sample_readings()) + " sample, " +
                    std::to_string(summary.reference_readings()) + " reference, " +
                    std::to_string(summary.dark_readings()) + " dark readings; " +
                    std::to_string(summary.operator_interventions()) + " operator actions";
  if (summary.estimated_duration_s() > 0) {
    out += "; rig time about " + Duration(RigSeconds(summary));
    if (time_scale != 1.0) {
      out += " at time scale " + Num(time_scale);
      if (real_rig_s > 0) out += " (" + Duration(real_rig_s) + " on a real rig)";
    }
    if (summary.physical_lower_bound_s() > 0) {
      out += ", at least " + Duration(summary.physical_lower_bound_s());
    }
    if (summary.operator_interventions() > 0) {
      out += "; plus the operator's " + std::to_string(summary.operator_interventions()) +
             " prompts, not counted (about " + Duration(plan::RigDescription{}.operator_action_s) +
             " each by hand)";
    }
  }
  return out;
}

void PrintPrompt(std::ostream& out, const v1::Prompt& prompt) {
  out << "prompt at step " << prompt.step_index() << " (" << PromptKindName(prompt.kind())
      << "): " << prompt.text() << "\n";
  if (!prompt.expected_action().empty()) {
    out << "  once answered, the daemon assumes: " << prompt.expected_action() << "\n";
  }
  if (prompt.has_target()) out << "  target: " << DirectionsText(prompt.target()) << "\n";
}

std::string FaultText(const v1::Fault& f) {
  std::string out = "fault at step " + std::to_string(f.step_index()) + " (attempt " +
                    std::to_string(f.attempt()) + "): " + f.code();
  if (f.code() == "device_error") out += " " + std::to_string(f.device_code());
  out += ": " + f.reason();
  // An adaptive session's skipped pose (the daemon's reason starts "step skipped: "): it runs on.
  const bool skipped = f.reason().rfind("step skipped: ", 0) == 0;
  out += f.will_retry() ? " — will retry"
         : skipped      ? " — the session goes on"
                        : " — session paused; `brdfctl resume` retries";
  return out;
}

void PrintSessionDetail(std::ostream& out, const v1::Session& s) {
  out << "session " << s.session_id() << "  \"" << s.name() << "\"\n";
  out << "  state        " << StateName(s.state()) << "\n";
  if (!s.state_reason().empty() && s.state_reason() != s.end_reason()) {
    out << "  why          " << s.state_reason() << "\n";
  }
  out << "  progress     " << ProgressText(s.progress()) << "\n";
  if (s.eta_s() > 0) out << "  ETA          " << Duration(s.eta_s()) << "\n";
  if (s.current_step() >= 0) out << "  step         " << s.current_step() << "\n";
  if (s.has_grid()) out << "  wavelengths  " << GridText(s.grid()) << "\n";
  if (s.last_quality_code() >= 0) {
    out << "  last quality " << s.last_quality_code() << (s.last_quality_code() == 0 ? " (ok)" : "")
        << "\n";
  }
  if (s.has_pending_prompt()) {
    const v1::Prompt& p = s.pending_prompt();
    out << "  prompt       step " << p.step_index() << " (" << PromptKindName(p.kind())
        << "): " << p.text() << "\n";
    out << "               when done: brdfctl answer " << s.session_id() << " " << p.step_index()
        << "\n";
  }
  if (s.has_last_fault()) out << "  last fault   " << FaultText(s.last_fault()) << "\n";
  out << "  created      " << TimeText(s.created_at()) << "\n";
  if (s.has_started_at()) out << "  started      " << TimeText(s.started_at()) << "\n";
  if (s.has_finished_at()) out << "  finished     " << TimeText(s.finished_at()) << "\n";
  if (!s.end_reason().empty()) out << "  end reason   " << s.end_reason() << "\n";
  if (s.has_summary()) out << "  plan         " << PlanSummaryText(s.summary()) << "\n";
  if (!s.plan().sample_description().empty()) {
    out << "  sample       " << s.plan().sample_description() << "\n";
  }
}

}  // namespace brdf::ctl
