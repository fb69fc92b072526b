"""Deploy profiles: one YAML file names every process of a system and how they talk.

A profile is validated before anything starts. Every error names the file, the
field path (``components[1].restart.policy``) and what was expected. Zenoh
endpoints must be on the loopback interface (or a unix socket) and multicast
scouting is off, unless the profile says ``allow_remote: true``: running across
hosts is an explicit choice, never the default. ``extends: base.yaml`` starts from
another profile and says only what differs (components are matched by name).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Annotated, Literal, get_args

from pydantic import Field, PlainValidator, ValidationError, model_validator
from pydantic_core import PydanticCustomError

from messages import topics
from messages.process import ParamValue
from profiles.access import EVERY_COMPONENT
from profiles.network import ZenohSettings
from profiles.profile_files import ProfileError, read_profile_data
from profiles.scene import Scene
from profiles.strict import StrictModel
from wbc.laws.gains import shown

COMPONENT_PACKAGE = "components"
"""The package of component modules: ``module: echo`` means ``components.echo``."""

Role = Literal["recorder", "driver", "estimator", "controller", "tool"]
ROLES: tuple[str, ...] = get_args(Role)
"""Start order of the roles; the launcher stops them in the reverse order: a recorder starts
first and stops last, once everything it records has stopped, so it drains all they sent."""

Identifier = Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*$")]
"""A lower-case Python identifier, also safe inside a key expression."""

Namespace = Annotated[str, Field(pattern=r"^[A-Za-z0-9_-]+(/[A-Za-z0-9_-]+)*$")]
"""One or more key-expression chunks without wildcards, e.g. ``sim`` or ``lab/robot1``."""


class RestartPolicy(StrictModel):
    """What the launcher does when a component exits.

    ``on-failure`` restarts after a non-zero exit, ``always`` after any exit,
    at most ``max_restarts`` times: the first restart at once (a driver that died comes back
    and stops its robot without waiting), then after ``backoff_initial_s`` doubled per
    restart up to ``backoff_max_s``. A run longer than ``reset_after_s`` resets the count.
    Exit code 2 (a configuration error) is never restarted.
    """

    policy: Literal["never", "on-failure", "always"] = "on-failure"
    max_restarts: int = Field(default=5, ge=0)
    backoff_initial_s: float = Field(default=0.5, gt=0.0)
    backoff_max_s: float = Field(default=10.0, gt=0.0)
    reset_after_s: float = Field(default=60.0, gt=0.0)

    @model_validator(mode="after")
    def _backoff_ordered(self) -> RestartPolicy:
        if self.backoff_max_s < self.backoff_initial_s:
            raise ValueError(
                f"backoff_max_s: expected >= backoff_initial_s ({self.backoff_initial_s})"
            )
        return self

    def backoff_s(self, restarts: int) -> float:
        """The wait before restart number ``restarts + 1``: none before the first."""
        if restarts == 0:
            return 0.0
        return min(self.backoff_initial_s * 2.0 ** (restarts - 1), self.backoff_max_s)


def _param_value(value: object) -> ParamValue:
    """A parameter's value as a profile gives it: a number, a flag, a word, or a list (of
    numbers, or of lists of numbers); what the component declares is checked later
    (``launch.graph.dataflow``)."""

    def numbers(row: object) -> bool:
        return isinstance(row, list | tuple) and all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in row
        )

    if isinstance(value, bool | int | float | str) or numbers(value):
        return value
    if isinstance(value, list | tuple) and all(numbers(row) for row in value):
        return value
    raise PydanticCustomError(
        "param_value",
        "expected a number, a flag, a word or a list of numbers (or of lists of numbers)",
    )


class ComponentSpec(StrictModel):
    """One process: ``python -m components.<module> --profile P --name <name>``."""

    name: Identifier
    module: Identifier
    role: Role
    params: dict[str, Annotated[ParamValue, PlainValidator(_param_value)]] = {}
    restart: RestartPolicy = RestartPolicy()
    enabled: bool = True
    clock: Literal["wall", "sim"] | None = None
    """This component's time: the host's, or the simulator's ``sim/clock``; None follows the
    profile's ``clock``, except for the component that publishes ``sim/clock`` (the simulator,
    a replayer), which always runs on its own, the host's, time."""
    stop_timeout_s: float = Field(default=5.0, gt=0.0)
    """Seconds this component gets to exit after SIGTERM before SIGKILL; for a ``recorder``,
    seconds without progress (CPU time spent): it writes all that waits, however long."""
    remap: dict[str, str] = {}
    """Topic name -> topic name: the component reads or writes the second where its code says
    the first (as ROS 2 remaps a node's topics). Both must carry the same message type."""
    after: list[Identifier] = []
    """Components of this role or an earlier one that the launcher waits to see alive before
    it starts this one (a driver after the emulator that makes its device); they stop after
    it."""

    @model_validator(mode="after")
    def _remaps_keep_the_message_type(self) -> ComponentSpec:
        for old, new in self.remap.items():
            for name in (old, new):
                if name not in topics.TOPICS:
                    raise ValueError(
                        f"remap: {name!r} is not a topic (have {', '.join(topics.TOPICS)})"
                    )
            if topics.TOPICS[old].type is not topics.TOPICS[new].type:
                raise ValueError(
                    f"remap: {old} carries {topics.TOPICS[old].type.__name__} and "
                    f"{new} {topics.TOPICS[new].type.__name__}"
                )
        return self

    def topic(self, topic: topics.Topic) -> topics.Topic:
        """The topic this component really uses where its code names ``topic``."""
        return topics.TOPICS[self.remap.get(topic.name, topic.name)]

    @property
    def module_path(self) -> str:
        """The dotted Python module this component runs."""
        return f"{COMPONENT_PACKAGE}.{self.module}"


class Profile(StrictModel):
    """A whole system: its namespace, its network, its clock and its processes."""

    namespace: Namespace
    zenoh: ZenohSettings = ZenohSettings()
    robot: Path | None = None
    scene: Scene | None = None
    """The markers and camera of the workspace, for the components that see them."""
    clock: Literal["wall", "sim"] = "wall"
    startup_timeout_s: float = Field(default=30.0, gt=0.0)
    """Seconds the launcher gives every component to become alive (its liveliness token seen
    by the router) before it fails the launch, naming those that are not. A component starts
    in about a second on an idle machine (its imports) and took over 10 s on a shared one;
    one that exits before it is alive fails the launch at once, whatever this is."""
    watchdog_s: float = Field(default=10.0, gt=0.0)
    """A component alive but answering no status query for this long (a stopped process, a
    handler that never returns) is hung: the launcher kills it and restarts it by its policy.
    It answers on its handler thread, behind the work queued there: at 3 s, a sound recorder
    starved of CPU on a shared machine (one core busy, two test systems) was killed and its
    recording lost. The robot does not wait for it: the drivers stop on their own command
    timeout (0.2 s) whatever the launcher does."""
    clock_timeout_s: float = Field(default=1.0, gt=0.0)
    """Host seconds after which a component on ``sim`` time whose clock has not moved says its
    clock stalled (a controller then commands zero)."""
    processes: Literal["separate", "shared"] = "separate"
    """``separate``: one process per component. ``shared``: the components that are not
    recorders and start ``after`` none run in one process (``components.container``), each with
    its own node and threads on one Zenoh session, so that the interpreter and its libraries
    load once and their samples to each other stay in the process (a lockstep experiment's). A
    fault that ends that process ends them all together: the launcher restarts each by its
    policy, in one new process."""
    components: list[ComponentSpec] = Field(min_length=1)

    @model_validator(mode="after")
    def _access_fits_the_components(self) -> Profile:
        access = self.zenoh.access
        if access is not None:
            users = access.users()
            for index, spec in enumerate(self.components):
                if spec.name not in users:
                    raise ValueError(
                        f"components[{index}].name: {spec.name!r} has no line in "
                        f"{access.credentials}; each component authenticates "
                        "as its name"
                    )
            names = [spec.name for spec in self.components]
            for name in access.parameters:
                if name != EVERY_COMPONENT and name not in names:
                    raise ValueError(
                        f"zenoh.access.parameters.{name}: names no component of "
                        f"the profile (have {', '.join(names)})"
                    )
        return self

    @model_validator(mode="after")
    def _unique_names(self) -> Profile:
        seen: dict[str, int] = {}
        for index, spec in enumerate(self.components):
            if spec.name in seen:
                raise ValueError(
                    f"components[{index}].name: {spec.name!r} is already used by "
                    f"components[{seen[spec.name]}]; names must be unique"
                )
            seen[spec.name] = index
        return self

    @model_validator(mode="after")
    def _starts_after_enabled_components(self) -> Profile:
        specs = {spec.name: spec for spec in self.components}
        for index, spec in enumerate(self.components):
            for name in spec.after if spec.enabled else ():
                other = specs.get(name)
                if other is None:
                    why = f"names no component (have {', '.join(specs)})"
                elif other is spec or not other.enabled:
                    why = "is itself" if other is spec else "is not enabled"
                elif ROLES.index(other.role) > ROLES.index(spec.role):
                    why = f"is a {other.role}, whose role starts after a {spec.role}'s"
                else:
                    continue
                raise ValueError(f"components[{index}].after: {name!r} {why}")
        for spec in self.components:
            if spec.enabled:
                self.start_depth(spec)  # a circle raises
        return self

    def start_depth(self, spec: ComponentSpec, chain: tuple[str, ...] = ()) -> int:
        """0 for a component that waits for none, else 1 + the deepest it waits for;
        ``ValueError`` for components that wait for each other in a circle."""
        if spec.name in chain:
            circle = " -> ".join((*chain, spec.name))
            raise ValueError(f"components: they wait for each other in a circle ({circle})")
        return max(
            (
                1 + self.start_depth(self.component(name), (*chain, spec.name))
                for name in spec.after
            ),
            default=0,
        )

    def component(self, name: str) -> ComponentSpec:
        """The component called ``name``; ``KeyError`` if the profile has none."""
        for spec in self.components:
            if spec.name == name:
                return spec
        raise KeyError(f"no component named {name!r} (have {[c.name for c in self.components]})")

    def clock_of(self, spec: ComponentSpec, publishes_clock: bool) -> str:
        """``"wall"`` or ``"sim"``: the time ``spec`` runs on (see ``ComponentSpec.clock``)."""
        if spec.clock is not None:
            return spec.clock
        return "wall" if publishes_clock else self.clock

    def shared(self) -> list[ComponentSpec]:
        """The enabled components that run in one process (``processes``): with ``shared``, those
        that are not recorders and start ``after`` none, when there are two or more."""
        specs = [s for s in self.start_order() if s.role != "recorder" and not s.after]
        return specs if self.processes == "shared" and len(specs) > 1 else []

    def start_order(self) -> list[ComponentSpec]:
        """The enabled components, drivers first, then estimators, controllers, tools."""
        enabled = [spec for spec in self.components if spec.enabled]
        return sorted(enabled, key=lambda spec: ROLES.index(spec.role))


def field_path(loc: tuple[int | str, ...]) -> str:
    """Render a pydantic error location as ``components[1].restart.policy``."""
    path = ""
    for part in loc:
        path += f"[{part}]" if isinstance(part, int) else (f".{part}" if path else str(part))
    return path


def _format_validation(path: Path, error: ValidationError) -> str:
    """One line per error. Model validators raise ``"sub.path: message"``, relative to the model."""
    lines = [f"{path}: invalid profile"]
    for item in error.errors():
        location = field_path(item["loc"])
        if item["type"] == "value_error":
            message = str(item["ctx"]["error"])
            lines.append(f"  {location}.{message}" if item["loc"] else f"  {message}")
        elif item["type"] == "missing":
            lines.append(f"  {location}: {item['msg']}")
        else:
            lines.append(f"  {location}: {item['msg']} (got {shown(item['input'])})")
    return "\n".join(lines)


def _check_files_and_modules(path: Path, profile: Profile) -> Profile:
    errors = []
    for index, spec in enumerate(profile.components):
        if importlib.util.find_spec(spec.module_path) is None:
            errors.append(
                f"  components[{index}].module: no module {spec.module_path!r} "
                f"(expected a module in the {COMPONENT_PACKAGE}/ package)"
            )
    robot = profile.robot
    if robot is not None:
        robot = (path.parent / robot).resolve()
        if not robot.is_file():
            errors.append(f"  robot: no robot description at {robot}")
    if errors:
        raise ProfileError("\n".join([f"{path}: invalid profile", *errors]))
    return profile.model_copy(update={"robot": robot})


def load_profile(path: str | Path) -> Profile:
    """Read and validate a profile; ``robot`` comes back as an absolute path.

    ``extends: base.yaml`` starts from another profile and overrides what the file says
    (see ``merge``). Raises ``ProfileError`` naming the file, the field and what was expected.
    """
    path = Path(path)
    data = read_profile_data(path)
    try:
        profile = Profile.model_validate(data)
    except ValidationError as error:
        raise ProfileError(_format_validation(path, error)) from error
    return _check_files_and_modules(path, profile)
