"""`parsimony bench`'s section 6.3 is `parsimony reproduce`'s: the same laws, goals and timing."""

from __future__ import annotations

import math
import statistics

from profiles.deploy_files import ROBOT_FILE, zoo
from studies.benchmark import convergence_test, format_report, run_bench
from studies.reproduce.efficiency import section_6_3
from studies.step_timing import lp_breakdown
from wbc.laws import lp_law
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)


def test_the_bench_runs_section_6_3_as_reproduce_runs_it():
    """Test 1's LP has no row but 5.10, test 2's LP no term, each test its own goal: the
    iterations of each law are those reproduce prints."""
    bench = convergence_test(ROBOT, 1)
    rows = {row.key: row.ours for row in section_6_3(ROBOT, 1)[0]}
    assert [bench["holonomic/classic"]["iterations"], bench["holonomic/lp"]["iterations"]] == (
        rows["6.3.test 1.iterations"]
    )
    assert [
        bench["nonholonomic/cascade"]["iterations"],
        bench["nonholonomic/lp"]["iterations"],
    ] == rows["6.3.test 2.iterations"]
    assert all(law["converged_trials"] == 1 for law in bench.values())


def test_the_zoo_bench_times_every_law_on_every_robot():
    """A quick run over the zoo: on every robot every law's step has a finite median and p99,
    and the LP's ratio to the classic law's is given; a differential base adds the cascade."""
    robots = zoo()
    assert ROBOT_FILE in robots
    timed = run_bench(20, 0, 0, zoo=robots, zoo_only=True)["zoo"]
    assert len(timed) == len(robots)
    for row in timed.values():
        laws = {"lp", "qp", "classic"} | ({"cascade"} if row["base"] == "differential" else set())
        assert laws <= row["step"].keys()
        for law in laws:
            figures = row["step"][law]
            assert 0.0 < figures["median_us"] <= figures["p99_us"] < math.inf
        assert 0.0 < row["lp_over_classic"] < math.inf
        assert row["dof"] == row["arm_dof"] + 3
        parts = row["lp_breakdown_us"]
        assert min(parts["kinematics"], parts["rows"], parts["vertex"]) > 0.0
    assert "LP / classic" in format_report({"zoo": timed})


def test_the_zoo_timed_several_times_gives_each_runs_glue_share_and_their_median():
    """Two runs of one robot: the glue's share of the LP step in each run, their median and range,
    and the table's columns for them; every figure the median of the two runs'."""
    [robot] = [path for path in zoo() if path.stem == "youbot"]
    [row] = run_bench(20, 0, 0, zoo=[robot], zoo_only=True, runs=2)["zoo"].values()
    share = row["glue_share"]
    assert len(share["runs"]) == 2 and all(math.isfinite(value) for value in share["runs"])
    assert share["median"] == statistics.median(share["runs"])
    assert (share["low"], share["high"]) == (min(share["runs"]), max(share["runs"]))
    table = format_report({"zoo": {"youbot": row}})
    assert "glue share low" in table and "the median of 2 runs" in table
    assert 0.0 < row["step"]["lp"]["median_us"] <= row["step"]["lp"]["p99_us"]


def test_the_lp_breakdown_leaves_the_law_as_it_found_it():
    """The breakdown times the law's module functions (e' and the terms) for its timed law only:
    after it, the law's own functions are back, so no later step pays for the timers."""
    plain = (lp_law.error_rate, lp_law.terms)
    parts = lp_breakdown(MobileManipulator.from_yaml(ROBOT_FILE), 20)
    assert lp_law.error_rate is plain[0] and lp_law.terms is plain[1]
    assert min(parts["kinematics"], parts["rows"], parts["vertex"]) > 0.0
