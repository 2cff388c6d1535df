"""The trailing axle's climb by traction: the quasi-static model against hand derivations."""

import math

import pytest

from swivel_car_model import traction
from swivel_car_model.params import SwivelCarParams

P = SwivelCarParams()


def test_on_the_riser_face_the_closed_form_of_mu_one():
    # beta = 0, mu = 1: G = 2, c = ((L cos - r - (h - r)) / 2 + r + z sin) / (L cos).
    h, z = 0.08, 0.077
    L, r = P.wheelbase, P.r
    sin = h / L
    cos = math.sqrt(1 - sin ** 2)
    expected = ((L * cos - h) / 2 + r + z * sin) / (L * cos)
    assert traction.trailing_axle_min_com(P, h, z, 1.0) == pytest.approx(expected, rel=1e-12)


def test_below_the_radius_the_edge_contact_helps():
    # h = r / 3: sin(beta) = 2/3; with mu = 1 the friction cone still misses the vertical.
    h, z, mu = P.r / 3.0, 0.0, 1.0
    sin_b = 2.0 / 3.0
    cos_b = math.sqrt(1 - sin_b ** 2)
    gain = 1 + mu * (sin_b + mu * cos_b) / (cos_b - mu * sin_b)
    L, r = P.wheelbase, P.r
    cos_t = math.sqrt(1 - (h / L) ** 2)
    expected = (L * cos_t - r * cos_b) / gain / (L * cos_t) + r * cos_b / (L * cos_t)
    assert traction.trailing_axle_min_com(P, h, z, mu) == pytest.approx(expected, rel=1e-12)


def test_a_low_edge_inside_the_friction_cone_needs_no_traction():
    # tan(beta) >= 1/mu: pushing alone rolls the wheel onto the edge.
    assert traction.trailing_axle_min_com(P, 0.01, 0.05, 1.0) == 0.0


def test_less_friction_needs_the_mass_further_forward():
    for h in (0.03, 0.06, 0.08, 0.12):
        assert traction.trailing_axle_min_com(P, h, 0.05, 0.8) > \
            traction.trailing_axle_min_com(P, h, 0.05, 1.0)


def test_limit_is_the_first_height_the_layout_misses():
    limit = traction.trailing_axle_limit(P, 0.47, 0.077, 1.0)
    assert traction.trailing_axle_min_com(P, limit, 0.077, 1.0) <= 0.47
    assert traction.trailing_axle_min_com(P, limit + 0.001, 0.077, 1.0) > 0.47
    assert traction.trailing_axle_limit(P, 0.24, 0.02, 1.0) < limit


@pytest.mark.parametrize('name, value', [('step_height', -0.01), ('step_height', math.nan),
                                         ('step_height', 1.0), ('mu', -1.0),
                                         ('com_height', math.inf)])
def test_bad_input_is_refused_with_its_name(name, value):
    args = {'step_height': 0.05, 'com_height': 0.05, 'mu': 1.0, name: value}
    with pytest.raises(ValueError, match=name):
        traction.trailing_axle_min_com(P, **args)
