"""InputSync: ticks see one moment of every input, whatever order the messages come in."""

import itertools

import pytest

from swivel_car_planner.core.sync import InputSync

TOPICS = ('joint_states', 'imu', 'odom', 'controller')


def feed(sync, messages):
    ticks = []
    for topic, stamp in messages:
        ticks += sync.add(topic, stamp, f'{topic}@{stamp}')
    return ticks


def cycle(t):
    return [(topic, t) for topic in TOPICS]


@pytest.mark.parametrize('order', list(itertools.permutations(TOPICS)))
def test_any_arrival_order_gives_the_same_ticks(order):
    sync = InputSync(TOPICS, 'controller')
    messages = [(topic, round(0.01 * k, 2)) for k in range(1, 4) for topic in order]
    ticks = feed(sync, messages)
    assert [tick.time for tick in ticks] == [0.01, 0.02, 0.03]
    for tick in ticks:
        assert tick.values == {topic: f'{topic}@{tick.time}' for topic in TOPICS}


def test_a_tick_waits_for_every_input_of_its_moment():
    sync = InputSync(TOPICS, 'controller')
    assert feed(sync, [('controller', 1.0), ('joint_states', 1.0), ('imu', 1.0)]) == []
    assert feed(sync, [('odom', 0.99)]) == []  # older odom: 1.0's may still come
    [tick] = feed(sync, [('odom', 1.0)])
    assert tick.values['odom'] == 'odom@1.0'


def test_a_slower_input_gives_its_newest_message_before_the_tick():
    sync = InputSync(TOPICS, 'controller')
    ticks = feed(sync, cycle(1.0) + [('controller', 1.01), ('joint_states', 1.01),
                                     ('odom', 1.01), ('imu', 1.02)])
    assert [tick.time for tick in ticks] == [1.0, 1.01]
    assert ticks[1].values['imu'] == 'imu@1.0'


def test_repeated_stamps_tick_once_and_a_reset_starts_over():
    sync = InputSync(TOPICS, 'controller')
    assert len(feed(sync, cycle(5.0) + cycle(5.0))) == 1
    # Time goes back (sim reset): the old messages must not answer the new moments.
    ticks = feed(sync, cycle(0.01))
    assert [tick.time for tick in ticks] == [0.01]
    assert set(ticks[0].values.values()) == {f'{topic}@0.01' for topic in TOPICS}


def test_a_tick_whose_inputs_were_dropped_is_skipped():
    sync = InputSync(TOPICS, 'controller', depth=2)
    feed(sync, [('controller', 1.0)])
    # odom of 1.0 never comes and its buffer moves past it.
    ticks = feed(sync, [('odom', 1.01), ('odom', 1.02), ('joint_states', 1.0), ('imu', 1.0)])
    assert ticks == []


def test_bad_construction_is_refused():
    with pytest.raises(ValueError, match='tick topic'):
        InputSync(TOPICS, 'clock')
    with pytest.raises(ValueError, match='depth'):
        InputSync(TOPICS, 'controller', depth=0)


def test_describe_names_each_topics_newest_stamp_and_the_waiting_tick():
    sync = InputSync(TOPICS, 'controller')
    feed(sync, [('controller', 1.0), ('imu', 1.0)])
    assert sync.describe() == ('newest stamps: joint_states none, imu 1.00 s, odom none, '
                               'controller 1.00 s; oldest waiting tick 1.00 s')
