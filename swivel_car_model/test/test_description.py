import math

import numpy as np
import pytest

from swivel_car_model.description import CarDescription, PARAMETERS
from swivel_car_model.params import SwivelCarParams


def test_mass_and_inertia_are_derived_from_the_layout():
    d = CarDescription()
    assert d.mass == pytest.approx(
        4 * d.wheel_mass + d.body_mass + d.rear_axle_mass + d.front_axle_mass
        + 2 * d.column_mass)
    # Nearly all the mass in the central body: I_s by hand is the box about its own centre
    # plus the parallel-axis term.
    heavy = CarDescription(body_mass=10.0, rear_axle_mass=1e-3, front_axle_mass=1e-3,
                           column_mass=1e-3, wheel_mass=1e-3)
    apex_x, apex_z = heavy.apex[0], heavy.apex[2]
    size_x, size_z = 0.4 * heavy.l, 0.25 * heavy.l
    # The 1e-3 kg parts add 1.11e-3 of the total (with 1e-4 kg parts 1.11e-4: theirs, not a
    # rounding); a box term or parallel-axis term wrong would be off by far more.
    assert heavy.inertia_about_rear_axle == pytest.approx(
        10.0 * (apex_x ** 2 + apex_z ** 2) + 10.0 * (size_x ** 2 + size_z ** 2) / 12.0,
        rel=2e-3)


def test_the_centre_of_mass_follows_the_body():
    back, forward = CarDescription(body_offset=-0.05), CarDescription(body_offset=0.05)
    shift = forward.com[0] - back.com[0]
    assert shift == pytest.approx(0.1 * CarDescription().body_mass / CarDescription().mass)
    assert 0.0 < back.com_fraction < forward.com_fraction < 1.0


def test_model_params_carry_the_geometry_gains_and_derived_inertia():
    d = CarDescription(l=0.3, phi=0.9, kp=12.0)
    p = d.model_params()
    assert isinstance(p, SwivelCarParams)
    assert (p.l, p.phi, p.kp) == (0.3, 0.9, 12.0)
    assert p.mass == pytest.approx(d.mass)
    assert p.inertia == pytest.approx(d.inertia_about_rear_axle)
    assert p.wheelbase == pytest.approx(d.wheelbase)
    np.testing.assert_allclose(p.apex, d.apex)


def test_from_values_takes_integers_for_floats_and_names_bad_values():
    d = CarDescription.from_values({'body_mass': 8, 'rear_differential': 'locked'})
    assert d.body_mass == 8.0 and isinstance(d.body_mass, float)
    for values, message in [({'mass': 21.0}, 'unknown'), ({'body_mass': -1.0}, 'body_mass'),
                            ({'r': math.nan}, 'r must be'), ({'kp': 'stiff'}, 'kp'),
                            ({'front_differential': 'welded'}, 'front_differential'),
                            ({'body_offset': 1.0}, 'body_offset'), ({'phi': 2.0}, 'phi'),
                            ({'wheel_friction': True}, 'wheel_friction')]:
        with pytest.raises(ValueError, match=message):
            CarDescription.from_values(values)


def test_every_field_is_a_parameter_with_a_unit():
    for name, (default, description) in PARAMETERS.items():
        assert getattr(CarDescription(), name) == default
        assert description.endswith(']') or isinstance(default, str), name


def test_the_shipped_designs_are_valid_descriptions():
    from pathlib import Path

    import yaml
    designs = sorted((Path(__file__).resolve().parents[1] / 'config' / 'designs').glob('*.yaml'))
    assert designs
    for path in designs:
        values = yaml.safe_load(path.read_text())['/**']['ros__parameters']
        description = CarDescription.from_values(values)
        assert description.mass == pytest.approx(21.0), path.name


def test_the_forward_body_design_has_the_measured_layout():
    d = CarDescription(body_mass=14.0, body_offset=0.05, rear_axle_mass=1.2)
    assert d.com_fraction == pytest.approx(0.594, abs=1e-3)
    assert d.inertia_about_rear_axle == pytest.approx(1.908, abs=1e-3)
