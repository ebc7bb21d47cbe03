"""BrdfClient: brdfd's gRPC API (proto/brdf/v1/brdf.proto) as Python methods.

    from brdf_client import BrdfClient
    with BrdfClient("127.0.0.1:50051", token="...") as brdf:
        session = brdf.submit_plan("examples/plans/demo.json", start_now=True)
        final = brdf.wait(session.session_id, on_event=lambda e: print(e.describe()))
        data = brdf.load_readings(session.session_id)            # ReadingSet: NumPy arrays
        r = brdf.interpolate(session.session_id, 30, 40, 160)      # InterpolationResult
        print(r.status, r.wavelengths, r.spectrum, r.vertex_ids, r.weights)

Control calls return the API's own messages (brdf_pb2.Session, RigStatus, ValidatePlanResponse:
their fields are documented in brdf.proto); data and interpolation calls return NumPy-based
objects (ReadingSet, InterpolationResult, InterpolationBatch). Every failed call raises BrdfError
with the gRPC status code and the daemon's message.

Units: degrees for angles, nm for wavelengths, sr⁻¹ for a BRDF, W·m⁻²·sr⁻¹·nm⁻¹ for radiance.
"""

import os
import time
from typing import (Any, Callable, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple,
                    Union)

import grpc

from . import grid_calls, names
from .appearance import Appearance, illuminant_enums
from ._stubs import brdf_pb2, brdf_pb2_grpc
from .errors import BrdfError
from .events import Event
from .export import ExportResult, export_request, format_name, part_path
from .interpolation import (InterpolationBatch, InterpolationResult, direction_query,
                            interpolation_options)
from .plans import PlanLike, to_plan
from .progress import Bar
from .readings import ReadingSet, kinds_to_enums

# The API's messages (brdf_pb2.Session, Prompt, RigStatus, ...) are generated at run time and
# carry no type information: they are Any here, and brdf.proto documents their fields.
Message = Any
PemSource = Union[bytes, str, "os.PathLike[str]", None]
Kinds = Union[str, int, Sequence[Union[str, int]], None]


def _read_pem(value: PemSource, what: str) -> Optional[bytes]:
    """PEM bytes from bytes, or from a file path."""
    if value is None or isinstance(value, bytes):
        return value
    try:
        with open(value, "rb") as f:
            return f.read()
    except OSError as e:
        raise ValueError(f"cannot read the {what} {value}: {e.strerror}") from e


def _save_export_stream(call: Iterable[Any], partial: str,
                        on_progress: Callable[[str, float], None],
                        parts: Optional[Dict[str, List[Any]]] = None) -> Message:
    """Writes an Export stream's bytes to `partial`, checking that they come in order and add up
    to the report's count; returns the report. Companion parts (ExportData.part, with
    include_uncertainty) go to `partial`.<part>, recorded in `parts` as {part: [path, bytes]}.
    BrdfError (the daemon's code, or DATA_LOSS)."""
    rpc = "Data.Export"
    received_parts: Dict[str, List[Any]] = {} if parts is None else parts

    def broken(message: str) -> BrdfError:
        return BrdfError(grpc.StatusCode.DATA_LOSS, f"{message}; export again", rpc)

    def write_part(data: Any) -> None:
        entry = received_parts.setdefault(data.part, [f"{partial}.{data.part}", 0])
        if data.offset != entry[1]:
            raise broken(f"part {data.part!r}: bytes at offset {data.offset} after {entry[1]}")
        with open(entry[0], "ab" if entry[1] else "wb") as pf:
            pf.write(data.content)
        entry[1] += len(data.content)

    received, report = 0, None
    with open(partial, "wb") as f:
        try:
            for chunk in call:
                kind = chunk.WhichOneof("payload")
                if kind == "progress":
                    on_progress(chunk.progress.stage, chunk.progress.fraction)
                elif kind == "data" and chunk.data.part:
                    write_part(chunk.data)
                elif kind == "data":
                    if chunk.data.offset != received:
                        raise broken(f"the daemon sent bytes at offset {chunk.data.offset} "
                                     f"after {received} bytes")
                    f.write(chunk.data.content)
                    received += len(chunk.data.content)
                elif kind == "report":
                    report = chunk.report
        except grpc.RpcError as e:
            raise BrdfError.from_rpc_error(e, rpc) from None
    if report is None:
        raise broken(f"the stream ended without a report after {received} bytes")
    if report.bytes != received:
        raise broken(f"the report counts {report.bytes} bytes but {received} came")
    for part in report.parts:
        got = received_parts.get(part.name, ["", 0])[1]
        if got != part.bytes:
            raise broken(f"the report counts {part.bytes} bytes of part {part.name!r} but {got} "
                         "came")
    return report


class BrdfClient:
    """A connection to one brdfd.

    Args:
      address: "host:port" (e.g. "127.0.0.1:50051", the daemon's [server] listen) or
               "unix:/path/to/socket".
      token:   the bearer token ([[auth.tokens]] in the daemon's configuration); sent as
               "authorization: Bearer <token>" on every call. None: $BRDF_TOKEN if set, else no
               token (for a daemon configured without tokens). An "analyst" token may only read;
               an "operator" token may call everything.
      tls:     connect over TLS ([server.tls] in the daemon's configuration). Implied by any of
               the three certificate arguments.
      root_certificates: PEM (bytes or a file path) of the CA that signed the daemon's
               certificate; None: the system's trust store.
      client_certificate, client_key: PEM (bytes or paths) for mutual TLS (the daemon's
               [server.tls] client_ca).
      server_name: the name to check the daemon's certificate against, when it differs from the
               address' host (e.g. connecting by IP to a certificate issued for "rig-pc").
      timeout: deadline of unary calls, seconds. Streams take their own `timeout` (default none).
    """

    def __init__(self, address: str, token: Optional[str] = None, *, tls: bool = False,
                 root_certificates: PemSource = None, client_certificate: PemSource = None,
                 client_key: PemSource = None, server_name: Optional[str] = None,
                 timeout: float = 30.0) -> None:
        self.address = address
        self.timeout = timeout
        if token is None:
            token = os.environ.get("BRDF_TOKEN") or None
        self._metadata: Tuple[Tuple[str, str], ...] = (
            (("authorization", f"Bearer {token}"),) if token else ())
        # Readings and batch chunks of a 401-band meter (a CS-2000) come near gRPC's default
        # 4 MiB; allow larger messages, as brdfctl does.
        options: List[Tuple[str, Any]] = [("grpc.max_receive_message_length", 64 * 1024 * 1024)]
        if server_name:
            options.append(("grpc.ssl_target_name_override", server_name))
        if tls or root_certificates or client_certificate or client_key:
            if bool(client_certificate) != bool(client_key):
                raise ValueError("mutual TLS needs both client_certificate and client_key")
            credentials = grpc.ssl_channel_credentials(
                root_certificates=_read_pem(root_certificates, "CA certificate"),
                private_key=_read_pem(client_key, "client key"),
                certificate_chain=_read_pem(client_certificate, "client certificate"))
            self._channel = grpc.secure_channel(address, credentials, options=options)
        else:
            self._channel = grpc.insecure_channel(address, options=options)
        self._control = brdf_pb2_grpc.ControlStub(self._channel)
        self._data = brdf_pb2_grpc.DataStub(self._channel)
        self._interp = brdf_pb2_grpc.InterpolationStub(self._channel)

    # --- connection ----------------------------------------------------------------------------

    def close(self) -> None:
        """Closes the channel (open streams end)."""
        self._channel.close()

    def __enter__(self) -> "BrdfClient":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def wait_ready(self, timeout: float = 10.0) -> None:
        """Blocks until the channel is connected; BrdfError(UNAVAILABLE) after `timeout` s."""
        try:
            grpc.channel_ready_future(self._channel).result(timeout=timeout)
        except grpc.FutureTimeoutError:
            raise BrdfError(grpc.StatusCode.UNAVAILABLE,
                            f"brdfd at {self.address} did not answer within {timeout:g} s; check "
                            "the address and that the daemon runs", "connect") from None

    def _unary(self, rpc: Callable[..., Any], request: Message, method: str,
               timeout: Optional[float] = None) -> Any:
        try:
            return rpc(request, metadata=self._metadata,
                       timeout=self.timeout if timeout is None else timeout)
        except grpc.RpcError as e:
            raise BrdfError.from_rpc_error(e, method) from None

    def _stream(self, rpc: Callable[..., Any], request: Message, method: str,
                timeout: Optional[float] = None) -> Iterator[Any]:
        call = rpc(request, metadata=self._metadata, timeout=timeout)
        try:
            for item in call:
                yield item
        except grpc.RpcError as e:
            raise BrdfError.from_rpc_error(e, method) from None
        finally:
            call.cancel()  # a no-op when the stream ended; frees it when the caller stopped early

    # --- Control: plans and sessions -----------------------------------------------------------

    def validate_plan(self, plan: PlanLike) -> Message:
        """Checks a plan (Plan, dict, JSON text or JSON file path) without storing it.

        Returns brdf_pb2.ValidatePlanResponse: .valid, .problems (field_path, message),
        .summary (step_count, sample_readings, operator_interventions, estimated_duration_s, ...).
        """
        return self._unary(self._control.ValidatePlan,
                           brdf_pb2.ValidatePlanRequest(plan=to_plan(plan)), "Control.ValidatePlan")

    def submit_plan(self, plan: PlanLike, start_now: bool = False) -> Message:
        """Stores a plan as a new session; returns the brdf_pb2.Session (QUEUED, or RUNNING).

        `plan`: a Plan message, a dict (the JSON form), JSON text, or a path to a JSON plan file.
        An invalid plan raises BrdfError(INVALID_ARGUMENT) listing every problem.
        """
        request = brdf_pb2.SubmitPlanRequest(plan=to_plan(plan), start_now=start_now)
        return self._unary(self._control.SubmitPlan, request, "Control.SubmitPlan").session

    def start(self, session_id: str) -> Message:
        """Starts a QUEUED session (it stays QUEUED while another one holds the rig)."""
        return self._unary(self._control.StartSession,
                           brdf_pb2.StartSessionRequest(session_id=session_id),
                           "Control.StartSession").session

    def pause(self, session_id: str, immediate: bool = False) -> Message:
        """Pauses a running session: after the current step (default), or at once (immediate:
        the step in progress is cancelled and run again on resume)."""
        mode = brdf_pb2.PAUSE_MODE_IMMEDIATE if immediate else brdf_pb2.PAUSE_MODE_DEFERRED
        return self._unary(self._control.PauseSession,
                           brdf_pb2.PauseSessionRequest(session_id=session_id, mode=mode),
                           "Control.PauseSession").session

    def resume(self, session_id: str) -> Message:
        """Resumes a PAUSED or PAUSING session."""
        return self._unary(self._control.ResumeSession,
                           brdf_pb2.ResumeSessionRequest(session_id=session_id),
                           "Control.ResumeSession").session

    def abort(self, session_id: str, reason: str = "") -> Message:
        """Stops a session for good (its readings are kept)."""
        return self._unary(self._control.AbortSession,
                           brdf_pb2.AbortSessionRequest(session_id=session_id, reason=reason),
                           "Control.AbortSession").session

    def answer_prompt(self, session_id: str, step_index: Optional[int] = None,
                      note: str = "") -> Message:
        """Confirms that the manual action of the pending prompt is done.

        step_index: the prompt's Prompt.step_index; None: the session's pending prompt (fetched
        first). A step_index that is not the pending prompt's raises FAILED_PRECONDITION, so a
        late answer never confirms the next prompt.
        """
        if step_index is None:
            session = self.get_session(session_id)
            if not session.HasField("pending_prompt"):
                raise BrdfError(grpc.StatusCode.FAILED_PRECONDITION,
                                f"session {session_id} has no pending prompt (state "
                                f"{names.state_name(session.state)})", "Control.AnswerPrompt")
            step_index = session.pending_prompt.step_index
        request = brdf_pb2.AnswerPromptRequest(session_id=session_id, step_index=step_index,
                                               note=note)
        return self._unary(self._control.AnswerPrompt, request, "Control.AnswerPrompt").session

    def get_session(self, session_id: str) -> Message:
        """One session, with its plan, progress, pending prompt and last fault."""
        return self._unary(self._control.GetSession,
                           brdf_pb2.GetSessionRequest(session_id=session_id), "Control.GetSession")

    def list_session_events(self, session_id: str) -> List[Message]:
        """The session's history of states, oldest first: SessionStateEvent (id, state, reason,
        at) messages, one when it was created and one per change of its state or reason."""
        reply = self._unary(self._control.ListSessionEvents,
                            brdf_pb2.ListSessionEventsRequest(session_id=session_id),
                            "Control.ListSessionEvents")
        return list(reply.events)

    def list_adaptive_rounds(self, session_id: str) -> List[Message]:
        """An adaptive session's rounds as stored on the rig, oldest first: AdaptiveRound messages
        (poses and their predicted gains, the uncertainty left before the round, the readings it
        was chosen from, its steps, the rig time and prompts spent before it and its own cost);
        empty for a session of another kind (docs/adaptive.md, "Every choice explained")."""
        reply = self._unary(self._control.ListAdaptiveRounds,
                            brdf_pb2.ListAdaptiveRoundsRequest(session_id=session_id),
                            "Control.ListAdaptiveRounds")
        return list(reply.rounds)

    def list_sessions(self, states: Union[str, int, Iterable[Union[str, int]], None] = None,
                      page_size: int = 0, limit: Optional[int] = None, *,
                      rig: Optional[str] = None, sample: Optional[str] = None,
                      material: Optional[str] = None, tag: Optional[str] = None,
                      created_after: Any = None, created_before: Any = None) -> List[Message]:
        """Sessions, newest first, optionally only those in `states` ("running", ...).

        Catalogue filters (brdfd for its own sessions, brdf-archive across the lab's rigs): `rig`
        (exactly), `sample` (the sample's id, or its name ignoring case), `material` (ignoring
        case), `tag` (one of the sample's tags), `created_after` / `created_before` (datetime or
        Unix seconds: created at or after / before).

        Follows the daemon's pages until `limit` sessions (None: all); `page_size` sets how many
        come per call (0: the daemon's 100). Session.plan is empty here; get_session returns it.
        """
        if isinstance(states, (str, int)):
            states = [states]
        wanted = [names.to_enum(s, names.STATES, "session state") for s in (states or [])]
        request = brdf_pb2.ListSessionsRequest(states=wanted, page_size=page_size,
                                               rig=rig or "", sample=sample or "",
                                               material=material or "", tag=tag or "")
        for field, when in (("created_after", created_after), ("created_before", created_before)):
            if when is not None:
                seconds = when.timestamp() if hasattr(when, "timestamp") else float(when)
                getattr(request, field).seconds = int(seconds)
        sessions: List[Message] = []
        token = ""
        while True:
            request.page_token = token
            page = self._unary(self._control.ListSessions, request, "Control.ListSessions")
            sessions.extend(page.sessions)
            token = page.next_page_token
            if limit is not None and len(sessions) >= limit:
                return sessions[:limit]
            if not token:
                return sessions

    def who_am_i(self) -> Message:
        """brdf_pb2.Caller: this client's token as the server knows it: `name` (the token's
        configured name, never the token), `role` ("operator" or "analyst") and `server`
        ("brdfd" or "brdf-archive"). UNAUTHENTICATED for a token the server does not know."""
        return self._unary(self._control.WhoAmI, brdf_pb2.WhoAmIRequest(), "Control.WhoAmI")

    def rig_status(self) -> Message:
        """brdf_pb2.RigStatus: devices' connection states, live pose, meter serial, active session."""
        return self._unary(self._control.GetRigStatus, brdf_pb2.GetRigStatusRequest(),
                           "Control.GetRigStatus")

    def watch(self, session_id: str, timeout: Optional[float] = None) -> Iterator[Event]:
        """An iterator of the session's events (Event): a snapshot, then state changes, prompts,
        step completions and faults, until the session ends. `timeout`: deadline of the whole
        stream, seconds (BrdfError DEADLINE_EXCEEDED when it passes); None: none.

            for event in brdf.watch(sid):          # Ctrl-C, break or .close() ends the stream
                print(event.kind, event.describe())
        """
        for event in self._stream(self._control.WatchSession,
                                  brdf_pb2.WatchSessionRequest(session_id=session_id),
                                  "Control.WatchSession", timeout):
            yield Event.from_proto(event)

    def wait(self, session_id: str, on_event: Optional[Callable[[Event], Any]] = None,
             on_prompt: Optional[Callable[[Message], Any]] = None,
             timeout: Optional[float] = None, poll_s: float = 10.0,
             stop_states: Iterable[Union[str, int]] = (),
             progress: Optional[bool] = None) -> Message:
        """Follows a session until it is terminal; returns the final brdf_pb2.Session.

        on_event(event): called for every Event (progress displays).
        on_prompt(prompt): called for each operator prompt (brdf_pb2.Prompt) once; when given, the
            prompt is answered after it returns (unless it returns False) — a script that does the
            manual action itself, e.g. setting the simulator's mounted target. None: prompts are
            left for the operator.
        timeout: give up after this many seconds (BrdfError DEADLINE_EXCEEDED); None: never.
        poll_s: the watch is renewed this often, so a prompt is seen even if its event was lost by
            a slow watcher (a renewed watch starts with a snapshot holding the pending prompt).
        stop_states: also return when the session enters one of these states (short names),
            e.g. ("paused",) to stop waiting when a fault pauses the session (see last_fault).
        progress: a tqdm bar of the steps done (progress.py; None: when someone watches).
        Ctrl-C stops waiting (the session goes on in the daemon).
        """
        with Bar(progress, desc=f"session {session_id}", unit="step") as bar:
            def show(event: Event) -> None:
                p = (event.data.progress if event.kind in ("snapshot", "step_completed")
                     else None)
                if p is not None and p.total_steps:
                    bar.moveto(p.done_steps, total=p.total_steps)
                if on_event:
                    on_event(event)
            return self._wait(session_id, show, on_prompt, timeout, poll_s, stop_states)

    def _wait(self, session_id: str, on_event: Callable[[Event], Any],
              on_prompt: Optional[Callable[[Message], Any]], timeout: Optional[float],
              poll_s: float, stop_states: Iterable[Union[str, int]]) -> Message:
        stop = {names.to_enum(s, names.STATES, "session state") for s in stop_states}
        stop |= names.TERMINAL_STATES
        until = None if timeout is None else time.monotonic() + timeout
        answered: set = set()
        while True:
            left = None if until is None else until - time.monotonic()
            if left is not None and left <= 0:
                raise BrdfError(grpc.StatusCode.DEADLINE_EXCEEDED,
                                f"session {session_id} did not finish within {timeout:g} s",
                                "wait")
            span = poll_s if left is None else min(poll_s, left)
            try:
                for event in self.watch(session_id, timeout=span):
                    on_event(event)
                    state = (event.data.to if event.kind == "state_changed" else
                             event.data.state if event.kind == "snapshot" else None)
                    if state in stop:
                        break
                    prompt = None
                    if event.kind == "prompt":
                        prompt = event.data
                    elif event.kind == "snapshot" and event.data.HasField("pending_prompt"):
                        prompt = event.data.pending_prompt
                    # A prompt raised again (after a pause and resume) has a new raised_at.
                    key = None if prompt is None else (prompt.step_index,
                                                       prompt.raised_at.SerializeToString())
                    if prompt is not None and on_prompt and key not in answered:
                        answered.add(key)
                        if on_prompt(prompt) is not False:
                            self._answer_if_pending(session_id, prompt.step_index)
            except BrdfError as e:
                if e.code != grpc.StatusCode.DEADLINE_EXCEEDED:
                    raise
            session = self.get_session(session_id)
            if session.state in stop:
                return session

    def _answer_if_pending(self, session_id: str, step_index: int) -> None:
        try:
            self.answer_prompt(session_id, step_index, note="answered by brdf_client")
        except BrdfError as e:
            # Paused (or aborted) meanwhile: the prompt comes again on resume, and is answered then.
            if e.code != grpc.StatusCode.FAILED_PRECONDITION:
                raise

    # --- Data ----------------------------------------------------------------------------------

    def readings(self, session_id: str, kinds: Kinds = None, after_id: int = 0,
                 follow: bool = False, batch_size: Optional[int] = None,
                 timeout: Optional[float] = None,
                 progress: Optional[bool] = None) -> Iterator[ReadingSet]:
        """Yields the session's readings in id order, as ReadingSet chunks (NumPy arrays).

        kinds: "sample", "reference", "dark" or a list of them; None: all.
        after_id: only readings with a larger id (to resume).
        follow: keep going as new readings are taken, until the session ends.
        batch_size: readings per chunk; None: 1 when following (each as it lands), else 500.
        progress: a tqdm bar counting the readings (None: when someone watches).
        Ctrl-C, a break or .close() cancels the stream.
        """
        if batch_size is None:
            batch_size = 1 if follow else 500
        request = brdf_pb2.StreamReadingsRequest(session_id=session_id,
                                                 kinds=kinds_to_enums(kinds), after_id=after_id,
                                                 follow=follow)
        chunk: List[Message] = []
        with Bar(progress, desc=f"readings of session {session_id}", unit="reading") as bar:
            for reading in self._stream(self._data.StreamReadings, request,
                                        "Data.StreamReadings", timeout):
                chunk.append(reading)
                bar.update()
                if len(chunk) >= batch_size:
                    yield ReadingSet.from_protos(chunk)
                    chunk = []
        if chunk:
            yield ReadingSet.from_protos(chunk)

    def load_readings(self, session_id: str, kinds: Kinds = None, timeout: Optional[float] = None,
                      progress: Optional[bool] = None) -> ReadingSet:
        """Every stored reading of the session (of `kinds`) as one ReadingSet; .to_dataframe()
        and .to_dataarray() label it (pandas, xarray). progress: as readings()."""
        return ReadingSet.concat(self.readings(session_id, kinds=kinds, timeout=timeout,
                                               progress=progress))

    def export(self, session_id: str, fmt: Union[str, int], path: "str | os.PathLike[str]", *,
               quantity: Union[str, int, None] = None, method: Union[str, int] = "octant",
               axis_scale: Optional[Sequence[float]] = None, mirror_phi: bool = False,
               reciprocity: Optional[bool] = None, step_theta_i: float = 0.0,
               step_theta_o: float = 0.0, step_phi: float = 0.0, grid_nodes: bool = False,
               exclude_flagged: bool = False, chunk_bytes: int = 0, fill: str = "chain",
               rgb: bool = False, rgl_theta_i_count: int = 0, rgl_resolution: int = 0,
               on_progress: Optional[Callable[[str, float], Any]] = None,
               timeout: Optional[float] = None, coordinates: Union[str, int, None] = None,
               trend: Union[str, int, None] = None, progress: Optional[bool] = None,
               sidecar: bool = False, float32: bool = False,
               uncertainty: bool = False) -> ExportResult:
        """Has the daemon export the session as a file and saves it at `path`; returns an
        ExportResult (file name, bytes, summary, rows, cells, filled_cells, shape, ...).

        fmt: "csv" (the readings, one row each), "grid" (the session's interpolator on a regular
            (θi, θo, φ) grid: CSV when `path` ends in ".csv", else NumPy .npy, float64 (or float32) of shape
            (nθi, nθo, nφ, bands), NaN where the method cannot fill a cell), "merl" (a MERL
            .binary, 90 × 90 × 180 linear sRGB, −1 where unfilled), "rgl" (an RGL material .bsdf
            for Mitsuba 3 and pbrt-v4, spectral or with rgb=True linear sRGB; read it with
            brdf_client.rgl.read_rgl), "bird" (a BiRD universal BRDF JSON file: one point per
            sample reading and band with its BRDF and uBRDF, the combined standard uncertainty
            of the reading's stored budget, and the session's provenance; docs/bird-format.md);
            or "grid_npy", "grid_csv", "bird_json".
        path: the file; an existing folder: the daemon's file name (session-3-grid-brdf.npy, ...)
            in it. The bytes go to `path`.partial, which is renamed to `path` only once the
            report has arrived and the bytes are complete, so a failed or interrupted export never
            leaves a truncated file (the partial file is removed).
        quantity: csv and grids: "brdf" (sr⁻¹; None: the daemon's default, BRDF), "reflectance"
            or "radiance" (csv: every reading, raw). MERL, RGL and BiRD are always the BRDF.
        method, axis_scale, mirror_phi, coordinates, trend: grids, MERL and RGL, as interpolate() (a
            grid's .json sidecar records them). reciprocity: also
            use the θi↔θo swapped readings; None: on for MERL and RGL (a cell stands for a pair of
            directions and its swap alike, as `brdfctl export merl`), off otherwise.
        fill: grids, MERL, RGL: "chain" (cells the method cannot fill take Delaunay's value, then
            the fitted Cook-Torrance model's: no holes above the horizon) or "none" (NaN / −1);
            the result's fill counts where the values came from.
        rgb, rgl_theta_i_count, rgl_resolution: RGL: linear sRGB instead of spectra; θi slices
            (0: 24) and nodes per side of the warped square (0: 48).
        step_theta_i, step_theta_o, step_phi: grids: degrees, dividing 90 (θ) or 180 (φ);
            0: 1°. grid_nodes: sample 0, step, …, 90 (180) instead of the cells' centres.
        exclude_flagged: leave out readings the quality policy flagged.
        chunk_bytes: the daemon's largest data message; 0: 128 KiB.
        on_progress(stage, fraction): called for each progress message ("loading readings",
            "resampling", "building the MERL table", "sending", "done"; fraction in [0, 1],
            never decreasing).
        timeout: deadline of the whole export, seconds; None: none.
        progress: a tqdm bar of the stages (None: when someone watches). Ctrl-C cancels the
            export (the daemon stops) and removes the partial file.
        sidecar: grid .npy: also write its description as `path`.json, as brdfctl does
            (brdf_client.open_grid reads the pair).
        float32: grid .npy: float32 instead of float64, half the bytes (the sidecar's "dtype"
            says which); ValueError for other formats.
        uncertainty: grid .npy: also the cells' standard uncertainties (k = 1), three arrays of
            the grid's shape and dtype saved beside `path` as STEM.u.npy (combined),
            STEM.u_measurement.npy and STEM.u_interpolation.npy, named in the description's
            "uncertainty" (docs/uncertainty.md, "Exports"); MERL and RGL: STEM.uncertainty.json,
            the per-band summary of the cells' u. The result's `parts` maps each to its path.
            ValueError for the readings CSV, a grid as CSV and BiRD.

        Raises BrdfError with the daemon's code and message (NOT_FOUND for an unknown session,
        INVALID_ARGUMENT for bad steps or options, FAILED_PRECONDITION for a session without
        usable readings), DATA_LOSS when the stream has a gap or its byte count disagrees with
        the report, ValueError for a bad argument, OSError when the file cannot be written.
        """
        path = os.fspath(path)
        if not path:
            raise ValueError("give the file (or an existing folder) to save the export in")
        into_folder = os.path.isdir(path)
        request = export_request(session_id, fmt, "" if into_folder else path,
                                 quantity=quantity, method=method, axis_scale=axis_scale,
                                 mirror_phi=mirror_phi, reciprocity=reciprocity,
                                 coordinates=coordinates, trend=trend,
                                 step_theta_i=step_theta_i, step_theta_o=step_theta_o,
                                 step_phi=step_phi, grid_nodes=grid_nodes,
                                 exclude_flagged=exclude_flagged, chunk_bytes=chunk_bytes,
                                 fill=fill, rgb=rgb, rgl_theta_i_count=rgl_theta_i_count,
                                 rgl_resolution=rgl_resolution, float32=float32,
                                 uncertainty=uncertainty)
        partial = (os.path.join(path, f"brdf_client-export-{session_id}") if into_folder
                   else path) + ".partial"
        parts: Dict[str, List[Any]] = {}
        call = self._data.Export(request, metadata=self._metadata, timeout=timeout)
        try:
            with Bar(progress, total=100, desc=f"export {format_name(request.format)}",
                     unit="%") as bar:
                def show(stage: str, fraction: float) -> None:
                    bar.moveto(round(100 * fraction, 1), desc=stage)
                    if on_progress:
                        on_progress(stage, fraction)
                report = _save_export_stream(call, partial, show, parts)
            # basename: the daemon names a file, never where it goes.
            final = (os.path.join(path, os.path.basename(report.file_name)) if into_folder
                     else path)
            os.replace(partial, final)
            saved = {p.name: part_path(final, p.name, p.file_name) for p in report.parts}
            for name, to in saved.items():
                if name in parts:
                    os.replace(parts[name][0], to)
        except BaseException:
            call.cancel()  # stops the daemon's work when we gave up early (Ctrl-C included)
            for leftover in [partial] + [entry[0] for entry in parts.values()]:
                try:
                    os.remove(leftover)
                except OSError:
                    pass  # never created (or already gone); the error that matters is re-raised
            raise
        result = ExportResult.from_report(report, final, request.format, saved)
        if sidecar and result.description is not None:
            result.write_sidecar()
        return result

    def grid(self, session_id: str, step: grid_calls.Steps = 5.0, *,
             quantity: Union[str, int] = "brdf", method: Union[str, int] = "octant",
             fill: str = "chain", coordinates: Union[str, int, None] = None,
             trend: Union[str, int, None] = None, axis_scale: Optional[Sequence[float]] = None,
             mirror_phi: bool = False, reciprocity: Optional[bool] = None,
             grid_nodes: bool = False, exclude_flagged: bool = False, provenance: bool = True,
             path: Optional[str] = None, netcdf: Optional[str] = None,
             progress: Optional[bool] = None, timeout: Optional[float] = None) -> Any:
        """The session on a regular (θi, θo, φ) grid, exported by the daemon (Data.Export, as
        export(..., "grid")), as an xarray Dataset (brdf_client.grid_datasets documents it):

            ds = brdf.grid(sid, step=5)                        # 18 × 18 × 36 cells × bands
            ds.brdf.sel(theta_i=32.5, wavelength=552).plot()   # sr⁻¹ over (θo, φ)

        step: degrees for all three axes, or (θi, θo, φ); each divides 90 (θ) or 180 (φ); 0 is
            1°, a 1.2 GB grid. The cells are at the centres (grid_nodes: 0, step, …, 90).
        quantity, method, fill, coordinates, trend, axis_scale, mirror_phi, reciprocity,
            exclude_flagged: as export().
        provenance: with fill "chain", also export the grid with fill "none" by the method and
            by Delaunay (up to two more exports) to tell each cell's provenance (interpolated,
            fallback, model, empty); False: one export, the chain's cells "unrecorded".
        path: keep the .npy there, with its description as path.json (open_grid reads them);
            None: a temporary file, removed once the Dataset holds the values.
        netcdf: also write the Dataset there (write_netcdf: xarray's writer).
        progress: a tqdm bar per export (None: when someone watches). Ctrl-C cancels.
        Errors: as export().
        """
        return grid_calls.export_grid(
            self, session_id, step, method=method, fill=fill, provenance=provenance, path=path,
            netcdf=netcdf, progress=progress, quantity=quantity, coordinates=coordinates,
            trend=trend, axis_scale=axis_scale, mirror_phi=mirror_phi, reciprocity=reciprocity,
            grid_nodes=grid_nodes, exclude_flagged=exclude_flagged, timeout=timeout)

    # --- Interpolation -------------------------------------------------------------------------

    def interpolate(self, session_id: str, theta_i: float, theta_o: float,
                    phi: Optional[float] = None, *, phi_i: Optional[float] = None,
                    phi_o: Optional[float] = None, method: Union[str, int] = "octant",
                    quantity: Union[str, int] = "brdf",
                    axis_scale: Optional[Sequence[float]] = None, mirror_phi: bool = False,
                    reciprocity: bool = False, coordinates: Union[str, int, None] = None,
                    trend: Union[str, int, None] = None,
                    uncertainty: bool = False) -> InterpolationResult:
        """The spectrum at one direction, from the session's SAMPLE readings.

        Direction, degrees: (theta_i, theta_o, phi) for isotropic sessions (φ = |φo − φi| in
        [0, 180], 180 = specular side), or theta_i, theta_o with phi_i and phi_o (four angles).
        method: "octant" (the paper's), "delaunay" or "nearest".
        quantity: "brdf" (sr⁻¹), "reflectance" (ratio) or "radiance" (W·m⁻²·sr⁻¹·nm⁻¹).
        axis_scale, mirror_phi, reciprocity: brdf.proto's InterpolationOptions.
        coordinates: where the method measures and blends: "incidence" ((θi, θo, φ); None: the
            daemon's default, incidence) or "half_difference" / "half-diff" (Rusinkiewicz's
            half/difference angles; isotropic sessions only, else BrdfError INVALID_ARGUMENT).
            Directions and the vertices' coordinates stay (θi, θo, φ) either way.
        trend: "bivariate" blends the readings' residuals from a smooth f(θh, θd) fitted to all
            of them and adds it back (closer near a sharp specular peak; isotropic sessions only;
            docs/interpolation.md, "Bivariate trend"); None or "none": the readings' spectra.
        uncertainty: also the spectrum's standard uncertainties (result.uncertainty: measurement,
            shared, interpolation, combined per band; docs/uncertainty.md "Interpolated values").

        Returns an InterpolationResult (.to_dataset(): labelled, xarray). A direction the method
        cannot fill is not an error: check result.ok / result.status ("empty_octant",
        "outside_hull", ...).
        """
        direction: Tuple[float, ...]
        if (phi_i is None) != (phi_o is None):
            raise ValueError("give phi_i and phi_o together (four angles), or phi alone")
        if phi_i is not None:
            if phi is not None:
                raise ValueError("give either phi (isotropic) or phi_i and phi_o, not both")
            direction = (theta_i, phi_i, theta_o, float(phi_o or 0.0))
        else:
            if phi is None:
                raise ValueError("phi is missing: give (theta_i, theta_o, phi), degrees")
            direction = (theta_i, theta_o, phi)
        request = brdf_pb2.InterpolateRequest(
            session_id=session_id, method=names.to_enum(method, names.METHODS, "method"),
            quantity=names.to_enum(quantity, names.QUANTITIES, "quantity"),
            direction=direction_query(direction),
            options=interpolation_options(axis_scale, mirror_phi, reciprocity, coordinates,
                                          trend),
            include_uncertainty=uncertainty)
        response = self._unary(self._interp.Interpolate, request, "Interpolation.Interpolate")
        return InterpolationResult.from_proto(response.result)

    def appearance(self, session_id: str, illuminants: Union[str, Sequence[str], None] = None, *,
                   method: Union[str, int] = "octant", sphere_size: int = 0,
                   light: Optional[Sequence[float]] = None,
                   axis_scale: Optional[Sequence[float]] = None, mirror_phi: bool = False,
                   reciprocity: bool = False, coordinates: Union[str, int, None] = None,
                   trend: Union[str, int, None] = None) -> Appearance:
        """The sample's colour (CIE 45°:0°) and a lit sphere in sRGB
        (Interpolation.RenderAppearance, docs/appearance.md). illuminants: "D65", "A", a list of them, or None for both.
        sphere_size: pixels per side, at most 512 (0: 128). light: (x, y, z) towards the light
        (x right, y up, z towards the viewer), None for the default (upper left, in front).
        Returns an Appearance (appearance["D65"].hex, .xy, .sphere as an (n, n, 4) uint8 array)."""
        request = brdf_pb2.AppearanceRequest(
            session_id=session_id, method=names.to_enum(method, names.METHODS, "method"),
            options=interpolation_options(axis_scale, mirror_phi, reciprocity, coordinates,
                                          trend),
            sphere_size=sphere_size, light=list(light or []),
            illuminants=illuminant_enums(illuminants))
        response = self._unary(self._interp.RenderAppearance, request,
                               "Interpolation.RenderAppearance")
        return Appearance.from_proto(response)

    def interpolate_batch(self, session_id: str, directions: Any,
                          method: Union[str, int] = "octant", quantity: Union[str, int] = "brdf",
                          axis_scale: Optional[Sequence[float]] = None, mirror_phi: bool = False,
                          reciprocity: bool = False, chunk_size: int = 0,
                          timeout: Optional[float] = None,
                          coordinates: Union[str, int, None] = None,
                          trend: Union[str, int, None] = None,
                          progress: Optional[bool] = None,
                          uncertainty: bool = False,
                          uncertainty_shared: bool = False) -> InterpolationBatch:
        """Spectra at many directions: `directions` is (N, 3) (θi, θo, φ) or (N, 4)
        (θi, φi, θo, φo), degrees. Returns an InterpolationBatch in the order asked (spectra
        (N, m) with NaN rows where the method could not fill the direction; .to_dataset():
        labelled, xarray). progress: a tqdm bar of the directions answered (None: when someone
        watches); Ctrl-C cancels the stream. uncertainty: also each spectrum's standard
        uncertainties (batch.u_measurement, .u_interpolation, .u_combined, (N, m); each
        result's .uncertainty, its combined computed here from the two parts as the daemon
        computes Interpolate's); chunk_size is then at most 512. uncertainty_shared: also each
        answer's shared part (result.uncertainty.shared; else empty, to keep the stream small)."""
        queries = [direction_query(d) for d in directions]
        request = brdf_pb2.InterpolateBatchRequest(
            session_id=session_id, method=names.to_enum(method, names.METHODS, "method"),
            quantity=names.to_enum(quantity, names.QUANTITIES, "quantity"), directions=queries,
            options=interpolation_options(axis_scale, mirror_phi, reciprocity, coordinates,
                                          trend),
            chunk_size=chunk_size, include_uncertainty=uncertainty,
            include_uncertainty_shared=uncertainty_shared)
        results: List[Optional[InterpolationResult]] = [None] * len(queries)
        with Bar(progress, total=len(queries), desc=f"interpolating ({names.method_name(request.method)})",
                 unit="direction") as bar:
            for chunk in self._stream(self._interp.InterpolateBatch, request,
                                      "Interpolation.InterpolateBatch", timeout):
                for k, r in enumerate(chunk.results):
                    results[chunk.first_index + k] = InterpolationResult.from_proto(r)
                bar.update(len(chunk.results))
        missing = [i for i, r in enumerate(results) if r is None]
        if missing:
            raise BrdfError(grpc.StatusCode.INTERNAL,
                            f"the daemon answered {len(queries) - len(missing)} of {len(queries)} "
                            f"directions (first missing: index {missing[0]})",
                            "Interpolation.InterpolateBatch")
        return InterpolationBatch([r for r in results if r is not None])

    def interpolate_grid(self, session_id: str, *, theta_i: Any = None, theta_o: Any = None,
                         phi: Any = None, theta_h: Any = None, theta_d: Any = None,
                         phi_d: Any = None, method: Union[str, int] = "octant",
                         quantity: Union[str, int] = "brdf",
                         axis_scale: Optional[Sequence[float]] = None, mirror_phi: bool = False,
                         reciprocity: bool = False, coordinates: Union[str, int, None] = None,
                         trend: Union[str, int, None] = None, chunk_size: int = 0,
                         netcdf: Optional[str] = None, progress: Optional[bool] = None,
                         timeout: Optional[float] = None) -> Any:
        """A grid computed from interpolations (one InterpolateBatch), as an xarray Dataset.

        Axes, degrees (any sequences): theta_i, theta_o, phi — the grid is (θi, θo, φ) — or
        theta_h, theta_d, phi_d — Rusinkiewicz's half/difference angles (φh = 0); then every
        cell also has its (θi, θo, φ) as coordinates, and cells below the surface are NaN with
        status "below_horizon" (never asked). Each cell: the method's answer (status "ok",
        provenance "interpolated") or NaN (its status says why; provenance "empty"): no fill
        chain here (grid() has it).
        method, quantity, axis_scale, mirror_phi, reciprocity, coordinates, trend: as
        interpolate(). netcdf: also write the Dataset there. progress, timeout: as
        interpolate_batch().

            g = brdf.interpolate_grid(sid, theta_h=range(0, 90, 2), theta_d=[10, 30, 50],
                                      phi_d=[90])
            g.brdf.sel(wavelength=550, method="nearest").plot.line(x="theta_h")
        """
        axes = {"theta_i": theta_i, "theta_o": theta_o, "phi": phi, "theta_h": theta_h,
                "theta_d": theta_d, "phi_d": phi_d}
        return grid_calls.interpolate_grid(
            self, session_id, axes=axes, method=method, quantity=quantity, progress=progress,
            netcdf=netcdf, timeout=timeout, chunk_size=chunk_size, axis_scale=axis_scale,
            mirror_phi=mirror_phi, reciprocity=reciprocity, coordinates=coordinates,
            trend=trend)
