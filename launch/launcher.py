"""The launcher: one Zenoh router and one supervised process per component of a profile.

It opens the router the components connect to, starts the enabled components (a recorder
first and the others once it is alive, so that it records them from their first message; then
drivers, estimators, controllers, tools; one that waits for others, ``after``, once they are
alive), prefixes every line they print with the time and ``[name]``, restarts the ones that
exit according to their restart policy, reports liveliness changes and each change of a
component's ``state`` (its status), and on SIGINT, SIGTERM or the end of the duration
(counted from the moment every component is alive, so that a slow start-up does not eat into
it) stops them in the reverse order: SIGTERM, then SIGKILL after each one's ``stop_timeout_s``
(for a recorder, which stops last, ``stop_timeout_s`` without progress: it drains its backlog
however long that takes, and is killed only when it has spent no CPU time for that long).

The launch fails at start-up when a component is not alive within the profile's
``startup_timeout_s`` or stops for good before it ever was (a configuration error). A
watchdog asks every component for its status; one alive but silent for ``watchdog_s`` is
killed and restarted by its policy. Parameters set while a component runs are kept in a file
per component in the launch's runtime directory (``messages.process.RUNTIME_DIR_ENV``) that
its next start reads.

Children run in their own session, so a Ctrl-C reaches the launcher alone and
the stop order holds; a child whose launcher dies stops by itself
(``messages.process.PARENT_PID_ENV``).

With ``processes: shared`` the components that are not recorders and start ``after`` none run
in one process (``components.container``), started once the recorders are alive. Each is still
watched, reported and stopped by name, but a fault that ends that process (a kill, a component
found hung) ends them all, and those restarted by their policy start again together.

A child's process is started by ``launch.spawn`` and stopped by ``launch.stop``: it is forked by
the launch's fork server (``launch.fork_server``), which loads the components' modules while the
router opens, or is a new interpreter if the server is gone. The shared process is started
ahead, before the recorders are alive, and given the word to start its components then.
"""

from __future__ import annotations

import shutil
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import IO

import zenoh

from components import container
from launch.child import Child, Process
from launch.fork_server import ForkServer
from launch.output import Output
from launch.query import statuses
from launch.spawn import spawn
from launch.stop import stop_all
from messages import topics
from messages.process import EXIT_CONFIG_ERROR, EXIT_FOR_GOOD, parent_gone
from profiles.profile import ComponentSpec, Profile

POLL_S = 0.05
"""How often the launcher looks at its children and the clock."""

UNREPORTED_STATES = ("starting", "stopping")
"""States a component passes through that the launcher's own lines already say."""


class Launcher:
    """Runs and supervises the components of one profile."""

    def __init__(
        self,
        profile: Profile,
        profile_path: Path,
        out: IO[str] = sys.stdout,
        err: IO[str] = sys.stderr,
        pass_fds: tuple[int, ...] = (),
    ) -> None:
        """``profile`` as loaded from ``profile_path``, the file its components read; a file
        in memory at ``/proc/self/fd/N`` (``parsimony launch --record``) is one of
        ``pass_fds``, the descriptors the components inherit."""
        self.profile = profile
        self.profile_path = Path(profile_path).absolute()
        self.pass_fds = pass_fds
        self.output = Output(out, err)
        self.children = [Child(spec) for spec in profile.start_order()]
        self.recorders = [c.spec.name for c in self.children if c.spec.role == "recorder"]
        shared = profile.shared()
        self.shared = [c for c in self.children if c.spec in shared]
        """The children that run in one process."""
        self._stop_reason: str | None = None
        self._kept_params = Path()
        """A directory of one JSON file per component: the parameters set while it runs, kept
        for its restart; made by ``run`` and removed when it returns."""
        self._seen_alive: set[str] = set()
        """Components whose liveliness token the router has seen at least once."""
        self._starting_until: float | None = None
        self._duration_s: float | None = None
        self._deadline: float | None = None
        """When the duration ends: set once every component is alive."""
        self._ahead: dict[tuple[str, ...], Process] = {}
        """The processes started ahead, by the names of their children, waiting for the word to
        start them."""
        self._wake = threading.Event()
        """Set when the supervision loop has news before its next poll: a component came alive
        (those waiting for it start at once), a stop was asked."""
        self._server: ForkServer | None = None
        """The fork server of the children's processes, while ``run`` runs."""

    def run(self, duration_s: float | None = None) -> int:
        """Run until a stop signal, the duration (from the moment every component is alive),
        or no component is left; return 0 or 1.

        Must be called from the main thread (it installs SIGINT and SIGTERM handlers).
        """
        for stop_signal in (signal.SIGINT, signal.SIGTERM):
            signal.signal(stop_signal, self._on_signal)
        endpoints = ", ".join(self.profile.zenoh.router)
        self._duration_s = duration_s
        self._kept_params = Path(tempfile.mkdtemp(prefix="parsimony-params-"))
        # The server loads the modules while the router opens.
        self._server = ForkServer(self._modules(), self.output.say)
        try:
            return self._run_router(endpoints)
        finally:
            for ahead in self._ahead.values():
                self._end_ahead(ahead)
            self._server.close()
            shutil.rmtree(self._kept_params, ignore_errors=True)

    def _modules(self) -> list[str]:
        """The modules the children's processes run."""
        modules = {child.spec.module_path for child in self.children}
        return sorted(modules | ({container.MODULE} if self.shared else set()))

    def _run_router(self, endpoints: str) -> int:
        """``run`` once the fork server is on its way: the router, the children started and
        supervised, then stopped."""
        with zenoh.open(self.profile.zenoh.router_config(self.profile.namespace)) as router:
            self.output.say(f"router listening on {endpoints}, namespace {self.profile.namespace}")
            self._start_ahead()
            watcher = router.liveliness().declare_subscriber(
                topics.liveliness_selector(self.profile.namespace),
                self._on_liveliness,
                history=True,
            )
            try:
                self._start_ready()
                if self.recorders and len(self.recorders) < len(self.children):
                    self.output.say(
                        f"the others start once {' and '.join(self.recorders)} "
                        "alive, to be recorded from their first message"
                    )
                for child in self.children:
                    if child.waiting and child.spec.after:
                        self.output.say(
                            f"{child.spec.name} starts once {' and '.join(child.spec.after)} alive"
                        )
                self._starting_until = time.monotonic() + self.profile.startup_timeout_s
                self.output.say(
                    f"waiting for {len(self.children)} component(s) to come alive "
                    f"(at most {self.profile.startup_timeout_s:g} s)"
                )
                threading.Thread(target=self._watch, args=(router,), daemon=True).start()
                self._supervise()
            finally:
                for stop_signal in (signal.SIGINT, signal.SIGTERM):
                    signal.signal(stop_signal, signal.SIG_IGN)
                stop_all(self.children, self.profile, self.output)
                watcher.undeclare()
        failed = [child.spec.name for child in self.children if child.failed]
        if failed:
            self.output.say(f"failed: {', '.join(failed)}")
        return 1 if failed else 0

    def _on_signal(self, signum: int, _frame: object) -> None:
        """Main thread, between two polls: ask the supervision loop to stop."""
        self._stop_reason = signal.Signals(signum).name
        self._wake.set()

    def _on_liveliness(self, sample: zenoh.Sample) -> None:
        """Zenoh thread: report a component's token appearing or disappearing."""
        name = topics.component_of_liveliness_key(self.profile.namespace, str(sample.key_expr))
        alive = sample.kind == zenoh.SampleKind.PUT
        if alive:
            self._seen_alive.add(name)
            self._wake.set()  # whoever waited for it starts now, not at the next poll
        for child in self.children:
            if child.spec.name == name:
                child.alive, child.answered_at = alive, time.monotonic()
                if alive:
                    child.state = "running"
                elif child.stopping:
                    return  # no loss: the stop's own lines say what becomes of it
        self.output.say(f"{name} {'alive' if alive else 'lost'}")

    def _supervise(self) -> None:
        """Poll the children until a stop is asked, the duration ends or none is left."""
        while self._stop_reason is None:
            self._wake.clear()
            self._start_ready()
            now = time.monotonic()
            if self._deadline is not None and now >= self._deadline:
                self._stop_reason = "end of duration"
                break
            for child in self.children:
                code = None if child.process is None else child.process.poll()
                if code is not None:
                    self._on_exit(child, code, now)
                elif child.restart_at is not None and now >= child.restart_at:
                    self._start(child)
            if self._starting_until is not None:
                self._check_startup(now)
            self._kill_hung(now)
            if parent_gone():
                self._stop_reason = "the process that started it is gone"
                break
            if all(child.done for child in self.children):
                self._stop_reason = self._stop_reason or "no component left running"
                break
            self._wake.wait(POLL_S)
        self.output.say(f"stopping ({self._stop_reason})")

    def _watch(self, router: zenoh.Session) -> None:
        """Watchdog thread: ask every component for its status, twice per ``watchdog_s``; an
        answer proves its handler thread runs."""
        period = self.profile.watchdog_s / 2.0
        while self._stop_reason is None:
            started = time.monotonic()
            try:
                answered = statuses(router, self.profile.namespace, period)
            except zenoh.ZError:
                answered = {}
            now = time.monotonic()
            for child in self.children:
                status = answered.get(child.spec.name)
                if status is not None:
                    child.answered_at = now
                    self._report_state(child, status.state)
            time.sleep(max(0.0, period - (now - started)))

    def _report_state(self, child: Child, state: str) -> None:
        """Say a change of a component's ``state`` (a driver holding, a clock stalled...)."""
        if state == child.state or state in UNREPORTED_STATES or self._stop_reason is not None:
            return
        self.output.say(f"{child.spec.name} {state} (was {child.state})")
        child.state = state

    def _kill_hung(self, now: float) -> None:
        """Kill a component seen alive that answered no status query for ``watchdog_s``; its
        exit is then handled like any other (restart by policy)."""
        for child in self.children:
            silent_s = now - child.answered_at
            if child.process is not None and child.alive and silent_s > self.profile.watchdog_s:
                others = [c.spec.name for c in self.children if c.process is child.process]
                others.remove(child.spec.name)
                also = f" and {', '.join(others)}, in its process" if others else ""
                self.output.say(
                    f"{child.spec.name} hung: no status answer for {silent_s:.1f} s; "
                    f"killing it{also}"
                )
                child.process.kill()
                child.answered_at = now

    def _check_startup(self, now: float) -> None:
        """Until every component has been alive once: fail the launch when one stops for good
        before (a configuration error, say), or is not alive when the start-up timeout runs out."""
        refused = [
            c.spec.name
            for c in self.children
            if c.done and c.failed and c.spec.name not in self._seen_alive
        ]
        waiting = [
            c.spec.name for c in self.children if not c.done and c.spec.name not in self._seen_alive
        ]
        if refused:
            self._fail_startup(f"{', '.join(refused)} failed during start-up", refused)
        elif not waiting:
            self._starting_until = None
            until = "Ctrl-C"
            if self._duration_s is not None:
                self._deadline = now + self._duration_s
                until = f"the end of the {self._duration_s:g} s duration"
            self.output.say(f"all {len(self.children)} components alive; running until {until}")
        elif now >= self._starting_until:
            timeout = self.profile.startup_timeout_s
            unstarted = [
                f"{c.spec.name} waited for {', '.join(self._awaited(c.spec))}"
                for c in self.children
                if c.waiting
            ]
            more = f"; never started: {'; '.join(unstarted)}" if unstarted else ""
            self._fail_startup(
                f"{', '.join(waiting)} not alive after {timeout:.1f} s "
                f"(check its zenoh endpoints and its log){more}",
                waiting,
            )

    def _fail_startup(self, why: str, names: list[str]) -> None:
        self._starting_until = None
        for child in self.children:
            if child.spec.name in names:
                child.failed = True
        self._stop_reason = f"start-up failed: {why}"

    def _awaited(self, spec: ComponentSpec) -> list[str]:
        """The components that must have been alive before ``spec`` starts: its ``after``,
        and the recorders unless it is one."""
        return [*([] if spec.role == "recorder" else self.recorders), *spec.after]

    def _start_ready(self) -> None:
        """Start the children not started yet whose awaited components have all been
        alive."""
        for child in self.children:
            if child.waiting and self._seen_alive.issuperset(self._awaited(child.spec)):
                self._start(child)

    def _start(self, child: Child) -> None:
        """Start a child's process; a shared child's with the others of ``shared`` not running
        and not done (in the process started ahead for them, if it waits)."""
        group, key = [child], (child.spec.name,)
        if child in self.shared:  # the process started ahead is theirs alone
            group = [c for c in self.shared if c.process is None and not c.done]
            key = tuple(c.spec.name for c in self.shared)
        names = [c.spec.name for c in group]
        ahead, popen = self._ahead.pop(key, None), None
        if ahead is not None and list(key) == names and ahead.poll() is None:
            try:
                ahead.stdin.write("go\n")
                ahead.stdin.close()
                popen = ahead
            except OSError:  # it ended meanwhile
                pass
        if popen is None:
            self._end_ahead(ahead)
            popen = self._spawn(group)
        for member in group:
            member.process, member.waiting = popen, False
            member.started_at, member.restart_at, member.alive = time.monotonic(), None, False
        label = f"{', '.join(names)} in one process" if len(group) > 1 else child.spec.name
        module = container.MODULE if len(group) > 1 else child.spec.module_path
        self.output.say(f"started {label} ({module}, pid {popen.pid})")

    def _start_ahead(self) -> None:
        """The shared children's process, started while they wait for the recorders, ready to
        start them on the word (``_start``)."""
        if self.shared and all(c.waiting for c in self.shared):
            names = tuple(c.spec.name for c in self.shared)
            self._ahead[names] = self._spawn(self.shared, ahead=True)

    def _end_ahead(self, ahead: Process | None) -> None:
        if ahead is not None:
            ahead.kill()
            ahead.wait()

    def _spawn(self, group: list[Child], ahead: bool = False) -> Process:
        """``spawn`` the process of ``group`` with this launch's profile file, kept parameters,
        inherited descriptors and fork server."""
        specs, kept, fds = [c.spec for c in group], self._kept_params, self.pass_fds
        return spawn(specs, self.profile_path, kept, fds, self.output, ahead, self._server)

    def _on_exit(self, child: Child, code: int, now: float) -> None:
        """Decide what a child's exit means: done, failed, or a restart after a backoff."""
        spec, policy = child.spec, child.spec.restart
        child.process = None
        if now - child.started_at >= policy.reset_after_s:
            child.restarts = 0
        wanted = policy.policy == "always" or (policy.policy == "on-failure" and code != 0)
        final = code in (EXIT_CONFIG_ERROR, EXIT_FOR_GOOD)
        if final or not wanted or child.restarts >= policy.max_restarts:
            child.done, child.failed = True, code != 0
            if code == EXIT_CONFIG_ERROR:
                why = "; configuration error, not restarting"
            elif code == EXIT_FOR_GOOD:
                why = "; cannot go on, not restarting"
            elif wanted:
                why = f"; no restarts left ({child.restarts}/{policy.max_restarts})"
            else:
                why = ""
            self.output.say(f"{spec.name} exited with {code}{why}")
            return
        delay = policy.backoff_s(child.restarts)
        child.restarts += 1
        child.restart_at = now + delay
        self.output.say(
            f"{spec.name} exited with {code}; "
            f"restart {child.restarts}/{policy.max_restarts} in {delay:.1f} s"
        )
