"""Figure generation and the reproduction table."""

import math

import numpy as np
import pytest

from swivel_car_model import dynamics, figures, kinematics
from swivel_car_model.params import SwivelCarParams


def test_selected_figures_are_written(tmp_path):
    figures.main(['--out', str(tmp_path), '--only', '18', '25'])
    for number in (18, 25):
        data = (tmp_path / f'fig{number}.png').read_bytes()
        assert data.startswith(b'\x89PNG') and len(data) > 10_000
    assert not (tmp_path.parent / 'thesis_reproduction.md').exists()


def test_writing_the_table_keeps_the_hand_written_sections(tmp_path):
    doc = tmp_path / 'thesis_reproduction.md'
    doc.write_text(f'# old\n\n## Measured in physics\n\n{figures.HAND_WRITTEN}: kept.\n\n'
                   '| a |\n\n## Generated\n\nan old generated line\n')
    figures.write_table(doc, [], [])
    text = doc.read_text()
    assert f'{figures.HAND_WRITTEN}: kept.\n\n| a |' in text
    assert 'an old generated line' not in text and '# old' not in text


def test_every_required_figure_has_a_maker():
    required = {18, 20, 21, 25, 26, 27, 28, 29, 31, 32, 35, 38, 40, 48, 49, 50, 51, 54, 55, 56,
                57, 58, 60, 61}
    assert required <= set(figures.FIGURES)


def test_table_explains_every_claim_that_does_not_reproduce(tmp_path):
    claims = figures.headline_claims()
    assert len(claims) >= 15
    for claim in claims:
        assert claim.reproduces or claim.why_not, claim.claim
        assert '|' not in claim.claim + claim.thesis + claim.ours + claim.why_not
    doc = tmp_path / 'table.md'
    figures.write_table(doc, claims, ['fig18.png'])
    text = doc.read_text()
    assert text.count('\n| ') == len(claims) + 1
    assert '## Corrections to the thesis' in text


def test_thesis_peak_torque_is_linear_in_h():
    # Fig. 32 reproduces: the peak is the holding torque m g cos(phi/2) h / 2 at theta2 = 0+
    hs = np.array([0.1, 0.15, 0.2])
    peaks = [dynamics.climb_torque_energy(SwivelCarParams(h=h), 0.012)[0] for h in hs]
    expected = 21.0 * dynamics.GRAVITY * math.cos(math.pi / 6) * hs / 2
    np.testing.assert_allclose(peaks, expected, rtol=5e-3)


def test_thesis_quarter_turn_steering_reproduces():
    assert kinematics.steering_angle(SwivelCarParams(), -math.pi / 2) == pytest.approx(math.pi / 2)
