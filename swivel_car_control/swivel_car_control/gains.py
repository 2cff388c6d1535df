"""The swivel PID gains the controller uses by default, retuned against the sim.

Thesis Table 2 (kp 19 N m/rad, ki 11.45 N m/(rad s), kd 5.5 N m s/rad, the documented
starting point and ``SwivelCarParams``' defaults) is far too soft for the simulated car: the
swivel must lift the body (about 5 N m of gravity load at 0.5 rad), so with kp = 19 the
proportional term alone cannot hold it and the integral has to do the work: a 0.5 rad step
takes about 3 s to settle, and a 1.2 rad step overshoots by 18 % and does not settle within
3 s (stick-slip limit cycle). Sweeping (kp, ki, kd) on the sim's step responses (0 -> 0.5,
0.5 -> 0, 0 -> 1.2, 1.2 -> -1.2, 0 -> 0.1 rad, set-point rate limit 1.5 rad/s) and on the yaw
rate reached in tight turns gave the values below, together with the controller's
``integral_band`` of 0.05 rad (the integral winds up while the set point ramps away, then
holds the swivel a few hundredths of a radian past its target for seconds: at 1.3 rad that is
5 % more yaw rate): overshoot <= 0.5 %, 2 % settling 0.4-2.1 s, tight arcs within 1 % of the
asked yaw rate. kd = 8 is above 2 I / dt = 7.2 N m s/rad for the bare front T (I = 0.036
kg m^2) at 100 Hz, but the swivel always carries the body it lifts, and no chatter shows.
See README.md for the figures.
"""

TUNED_GAINS = {
    'kp': 150.0,  # [N m/rad]
    'ki': 200.0,  # [N m/(rad s)]
    'kd': 8.0,  # [N m s/rad]
}
