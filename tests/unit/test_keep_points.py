"""keep_points: the history of chosen points frozen at the committed state (interface points
that lost their partner keep their law state while inactive)."""

import numpy as np
import pytest

from rough_contact.interface.state import HistoryInterfaceState, InterfaceState, keep_points


def test_frozen_points_take_the_committed_values_the_others_the_trial_ones():
    committed = HistoryInterfaceState.zeros(4)
    trial = HistoryInterfaceState(np.arange(8.0).reshape(4, 2), np.ones((4, 2)),
                                  np.full(4, 2.0), np.full(4, 0.5))
    keep = np.array([False, True, False, True])
    out = keep_points(trial, committed, keep)
    for name in ("plastic_slip", "accumulated_slip", "slip_path", "h_min"):
        got, t, c = getattr(out, name), getattr(trial, name), getattr(committed, name)
        np.testing.assert_array_equal(got[keep], c[keep])
        np.testing.assert_array_equal(got[~keep], t[~keep])
    assert out.plastic_slip[0, 1] == 1.0 and np.isinf(out.h_min[1])
    assert trial.plastic_slip[1, 0] == 2.0          # the inputs are not modified


def test_states_of_different_types_are_refused():
    with pytest.raises(TypeError, match="cannot be frozen point by point"):
        keep_points(InterfaceState.zeros(2), HistoryInterfaceState.zeros(2),
                    np.array([True, False]))
