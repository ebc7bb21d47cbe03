"""Session events (WatchSession) in a form that is easy to branch on.

A stream starts with a snapshot of the session, then sends state changes, operator prompts, step
completions (with progress and ETA) and faults in order, and ends when the session is terminal.
"""

import dataclasses
import datetime
from typing import Any, Optional

from . import names


@dataclasses.dataclass
class Event:
    """One event of a session.

    Attributes:
      kind:       "snapshot", "state_changed", "prompt", "step_completed", "fault", and for
                  adaptive sessions "adaptive_round" and "adaptive_stop".
      session_id: the session it belongs to.
      sequence:   increases by one per event.
      time:       when it happened (datetime, UTC), or None when unset.
      data:       the event's message: Session, StateChange, Prompt, StepCompletion, Fault,
                  AdaptiveRound or AdaptiveStop (brdf.proto documents their fields).
      raw:        the brdf.v1.SessionEvent as received.
    """

    kind: str
    session_id: str
    sequence: int
    time: Optional[datetime.datetime]
    data: Any
    raw: Any

    @classmethod
    def from_proto(cls, event: Any) -> "Event":
        """From a brdf.v1.SessionEvent."""
        kind = event.WhichOneof("event") or ""
        when = None
        if event.HasField("time"):
            when = event.time.ToDatetime().replace(tzinfo=datetime.timezone.utc)
        return cls(kind=kind, session_id=event.session_id, sequence=event.sequence, time=when,
                   data=getattr(event, kind) if kind else None, raw=event)

    def describe(self) -> str:
        """One line for a log or a progress display."""
        d = self.data
        if self.kind == "snapshot":
            p = d.progress
            return (f"session {d.session_id} ({d.name}): {names.state_name(d.state)}, "
                    f"{p.done_steps}/{p.total_steps} steps")
        if self.kind == "state_changed":
            why = f" ({d.reason})" if d.reason else ""
            return f"{names.state_name(getattr(d, 'from'))} → {names.state_name(d.to)}{why}"
        if self.kind == "prompt":
            return f"prompt at step {d.step_index} ({names.prompt_kind_name(d.kind)}): {d.text}"
        if self.kind == "step_completed":
            p = d.progress
            return (f"step {d.step_index} {names.step_kind_name(d.kind)} done: "
                    f"{p.done_steps}/{p.total_steps} steps, {p.done_samples}/{p.total_samples} "
                    f"samples, ETA {d.eta_s:.0f} s")
        if self.kind == "fault":
            # An adaptive session's skipped pose ("step skipped: ...") does not pause it.
            skipped = d.reason.startswith("step skipped: ")
            retry = ("will retry" if d.will_retry
                     else "the session goes on" if skipped else "session paused")
            return f"fault at step {d.step_index} ({d.code}, attempt {d.attempt}, {retry}): {d.reason}"
        if self.kind == "adaptive_round":
            return (f"round {d.round}: {len(d.poses)} poses, predicted gain {d.predicted_gain:.3g}, "
                    f"uncertainty left {d.uncertainty_left:.3g}, chosen from {d.readings_used} "
                    f"readings; spent {d.spent_rig_s / 60:.1f} min of rig time and "
                    f"{d.spent_prompts} prompts, the round {d.rig_s / 60:.1f} min and "
                    f"{d.prompts} prompts more")
        if self.kind == "adaptive_stop":
            return (f"adaptive stop: {d.reason}; uncertainty left {d.uncertainty_left:.3g} after "
                    f"{d.rounds} round(s), {d.readings} readings")
        return self.kind
