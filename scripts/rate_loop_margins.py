#!/usr/bin/python3
"""Rate-loop crossover and phase margin of each airframe, with its own gains and with the S500's.

The loop of one body axis, as control/rate_control.h and the flight loop close it: the rate PID
(D on a first-order filtered derivative, IMU_DGYRO_CUTOFF), the airframe's authority alpha (the
angular acceleration one unit of normalised torque demand produces: max torque / inertia, as the
allocator normalises it), an integrator to body rate, the first-order motor lag and one sample of
the 500 Hz rate loop:  L(s) = PID(s) * alpha / (s (tau s + 1)) * exp(-s Ts).

alpha and tau are those of the MJCF models (the derivation in each gains file); the gains are the
gains files' and configs/controller.yaml's. Run: /usr/bin/python3 scripts/rate_loop_margins.py
"""
import numpy as np

S500 = (0.15, 0.2, 0.003)  # configs/controller.yaml roll/pitch rate P, I, D
S500_YAW = (0.2, 0.1, 0.0)
# name, axis, own gains (P, I, D), alpha [rad/s^2 per unit demand], motor lag [s]
AIRFRAMES = [
    ("quadrotor (S500)", "roll/pitch", S500, 128.9, 0.030),
    ("quadrotor (S500)", "yaw", S500_YAW, 10.86, 0.030),
    ("quad250", "roll/pitch", (0.029, 0.039, 0.00058), 1000.2, 0.015),
    ("quad250", "yaw", (0.017, 0.0086, 0.0), 126.3, 0.015),
    ("hexarotor", "roll/pitch", (0.078, 0.104, 0.0016), 247.5, 0.040),
    ("hexarotor", "yaw", (0.138, 0.069, 0.0), 15.7, 0.040),
    ("x2_like", "roll", S500, 140.5, 0.020),
    ("x2_like", "pitch", S500, 202.6, 0.020),
    ("x2_like", "yaw", S500_YAW, 17.3, 0.020),
]


def margins(gains, alpha, tau, d_cutoff_hz=30.0, ts=0.002):
    p, i, d = gains
    w = np.logspace(-1, 4, 200000)
    s = 1j * w
    loop = (p + i / s + d * s / (1 + s / (2 * np.pi * d_cutoff_hz))) * alpha / (s * (tau * s + 1)) * np.exp(-s * ts)
    k = np.argmin(np.abs(np.abs(loop) - 1.0))
    return w[k] / (2 * np.pi), 180.0 + np.degrees(np.angle(loop[k]))


def main():
    print("| airframe | axis | own gains: crossover, phase margin | S500 gains: crossover, phase margin |")
    print("|---|---|---|---|")
    for name, axis, gains, alpha, tau in AIRFRAMES:
        own = margins(gains, alpha, tau)
        s500 = margins(S500_YAW if axis == "yaw" else S500, alpha, tau)
        print(f"| {name} | {axis} | {own[0]:.1f} Hz, {own[1]:.0f} deg | {s500[0]:.1f} Hz, {s500[1]:.0f} deg |")


if __name__ == "__main__":
    main()
