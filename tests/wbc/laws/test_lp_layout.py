"""The buffers of the linear program 5.29 for one shape: the rows HiGHS reads (velocity rows
u_P - u_N, the one-norm row, residual rows [A_b -A_b -I], linear rows [A -A 0]) written out
by hand for a small problem; the costs of y, 2 w_b; a step's new numbers replace the last."""

from __future__ import annotations

import numpy as np
import pytest

from wbc.laws.lp_layout import INF, Layout, picker

A_B = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
B = np.array([7.0, 8.0])
A = np.array([[9.0, 10.0, 11.0]])


def small() -> Layout:
    """n = 3, one residual cost of two rows, one linear row, one one-norm row."""
    layout = Layout(((2, 3), (1, 3)), residual_count=1, norm_rows=1)
    layout.fill([A_B, A], [B])
    return layout


def test_the_rows_are_the_programs_columns_u_plus_u_minus_y() -> None:
    layout = small()
    assert (layout.n, layout.columns, layout.static_rows, layout.varying_rows) == (3, 8, 4, 3)
    expected = np.array(
        [
            [1, 0, 0, -1, 0, 0, 0, 0],  # u_P[i] - u_N[i]
            [0, 1, 0, 0, -1, 0, 0, 0],
            [0, 0, 1, 0, 0, -1, 0, 0],
            [1, 1, 1, 1, 1, 1, 0, 0],  # the one-norm of u
            [1, 2, 3, -1, -2, -3, -1, 0],  # A_b u - y <= -b
            [4, 5, 6, -4, -5, -6, 0, -1],
            [9, 10, 11, -9, -10, -11, 0, 0],  # A u
        ],
        dtype=float,
    )
    assert np.array_equal(layout.matrix, expected)
    assert np.array_equal(layout.varying, expected[4:])
    assert layout.residual_upper.tolist() == [-7.0, -8.0]
    assert layout.starts.tolist() == [0, 8, 16] and len(layout.indices) == 3 * 8


def test_a_new_step_replaces_the_rows_and_offsets() -> None:
    layout = small()
    layout.fill([-A_B, 2 * A], [np.zeros(2)])
    assert layout.varying[:, :3].tolist() == [[-1, -2, -3], [-4, -5, -6], [18, 20, 22]]
    assert layout.varying[:, 3:6].tolist() == [[1, 2, 3], [4, 5, 6], [-18, -20, -22]]
    assert layout.residual_upper.tolist() == [0.0, 0.0]
    changed = A_B.copy()
    layout.fill([changed, A], [B])
    changed[0, 0] = 100.0  # the same array with new numbers (not a kept one) is read anew
    layout.fill([changed, A], [B])
    assert layout.varying[0, 0] == 100.0 and layout.varying[0, 3] == -100.0


def test_the_costs_of_y_are_twice_each_residual_costs_weight() -> None:
    layout = Layout(((2, 3), (1, 3), (0, 3)), residual_count=2, norm_rows=0)
    assert np.isnan(layout.weights).all()  # no weight yet
    layout.weigh([0.5, 3.0])
    assert layout.cost.tolist() == [0, 0, 0, 0, 0, 0, 1.0, 1.0, 6.0]
    assert layout.row_weight.tolist() == [0.5, 0.5, 3.0]
    layout.weigh([0.5, 1.0])
    assert layout.cost[6:].tolist() == [1.0, 1.0, 2.0] and layout.weights == [0.5, 1.0]


def test_bounds_start_free_and_u_columns_nonnegative() -> None:
    layout = small()
    assert (layout.lower[:3] == -INF).all() and (layout.upper[:3] == INF).all()
    assert (layout.col_lower == 0).all() and (layout.col_upper == INF).all()


def test_an_empty_matrix_has_no_block() -> None:
    layout = Layout(((2, 3), (0, 3), (1, 3)), residual_count=1, norm_rows=0)
    assert [block.shape for block in layout.blocks] == [(2, 3), (1, 3)]
    layout.fill([A_B, np.zeros((0, 3)), A], [B])
    assert layout.varying[2, :3].tolist() == [9, 10, 11]


def test_rows_of_another_width_are_refused() -> None:
    with pytest.raises(ValueError, match=r"needs 3 columns, got one of \(1, 2\)"):
        Layout(((2, 3), (1, 2)), residual_count=1, norm_rows=0)


@pytest.mark.parametrize(("places", "picked"), [([], ()), ([1], ("b",)), ([0, 2], ("a", "c"))])
def test_picker_gives_a_tuple_however_many_places(places: list[int], picked: tuple) -> None:
    assert picker(places)(["a", "b", "c"]) == picked
