"""A comparison case that compares no switching times says so; its rows then report none."""

from moreau.analysis.cases import ClosedFormPath, CompareCase


class RecordedSwitches(CompareCase):
    """A case whose run always switches to sticking at t = 0.5 (no run needed)."""

    def _trajectory_error(self, res):
        return 0.0

    def _run_switches(self, res, h):
        return [(0.5, "S")]


def test_a_row_reports_its_switches_only_where_the_case_compares_them():
    case = RecordedSwitches()
    assert case.measure(10, 1.0, None, (0.0, None)) == (0.0, [(0.5, "S")], None)
    case.compares_switches = False
    assert case.measure(10, 1.0, None, (0.0, None)) == (0.0, [], None)


def test_the_cases_without_switches_to_compare_say_so():
    from moreau.scenes.box_incline import BoxInclineCase
    from moreau.scenes.double_pendulum_stop import DoublePendulumStopCase
    from moreau.scenes.slider_crank_clearance import SliderCrankClearanceCase
    from moreau.scenes.sliding_box import SlidingBoxCase
    assert not ClosedFormPath.compares_switches and not BoxInclineCase.compares_switches
    assert not DoublePendulumStopCase.compares_switches
    assert not SliderCrankClearanceCase.compares_switches       # inherited from the ideal crank
    assert SlidingBoxCase.compares_switches                         # each corner's stop
