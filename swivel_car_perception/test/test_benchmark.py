"""The detection benchmark runs and prints its table (its figures are the benchmark's)."""

from swivel_car_perception import benchmark


def test_the_benchmark_prints_every_figure(capsys):
    benchmark.run(steps=2, seed=1)
    out = capsys.readouterr().out
    for line in ('detection rate', 'false positives on flat ground', '| height |',
                 '| distance |', '| yaw |', '| width |', 'camera at 10 Hz', 'detector:'):
        assert line in out
    assert 'detection rate (all in range): 2/2' in out
