"""`parsimony bench`'s section 6.3 is `parsimony reproduce`'s: the same laws, goals and timing."""

from __future__ import annotations

from profiles.deploy_files import ROBOT_FILE
from studies.benchmark import convergence_test
from studies.reproduce.efficiency import section_6_3
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
