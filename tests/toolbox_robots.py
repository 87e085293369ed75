"""The IRB-6700-like arm as a roboticstoolbox-python ``DHRobot`` with dynamics.

An independent model of the arm in another library's dynamics, for calibration tests and
benchmarks: the toolbox's recursive Newton-Euler (``rne``) stands in for a second simulator.
Shared with faultgen: the parameters, all taken from robots/irb6700/README.md (masses, centres of
mass, principal inertias, gear ratios, motor inertias, Coulomb and viscous friction, the axis-2
balancing spring). Independent: the kinematic description (standard DH from the published
dimensions) and all the dynamics code (the toolbox's Newton-Euler, the spring by formula here).

What ``rne(q, qd, qdd)`` returns, arm side (joint torque = motor torque times G): the rigid-body
torque of the links, plus ``G^2 Jm qdd`` (motor inertia reflected through the gearbox, the rotor
spinning about a fixed axis, as MuJoCo's ``armature``), plus the motor-side friction referred to the
arm, ``G^2 B qd + G Tc sign(qd)``, with ``B`` the README's viscous and ``Tc`` its Coulomb friction
(``robot.nofriction(coulomb=True, viscous=True)`` removes it). Not in the toolbox and to be added by
formula where needed: the balancing spring (:func:`irb6700_balance_torque`) and the README's static
(Stribeck) friction excess ``G f_s exp(-(G qd / v_s)^2) sign(qd)``.
"""

import numpy as np
import roboticstoolbox as rtb

PI = np.pi

# Per link 1-6, from robots/irb6700/README.md, "Centres of mass and inertias". The centre of mass
# is in the MJCF body frame. The README's principal inertias are about MuJoCo's inertia frame
# (body_iquat): the identity for the boxes of links 1-3, and for the cylinders of links 4-6 a
# frame whose z is the cylinder axis, body x (links 4, 6) or body y (link 5). Written below about
# the body axes x, y, z, the tensors are diagonal (checked against mujoco's R_iquat diag R_iquat^T).
MASS = [340.0, 200.0, 230.0, 100.0, 45.0, 15.0]
COM = [(0.05, 0, -0.2), (0, 0, 0.5), (-0.1, 0, 0.2), (0.65, 0, 0), (0.02, 0, 0), (-0.03, 0, 0)]
INERTIA = [
    (22.3, 27.7, 34.7),
    (30.3, 29.5, 3.47),
    (7.42, 19.2, 19.2),
    (1.28, 4.72, 4.72),  # cylinder along body x: README (4.72, 4.72, 1.28)
    (0.437, 0.441, 0.437),  # cylinder along body y: README (0.437, 0.437, 0.441)
    (0.091, 0.05, 0.05),  # cylinder along body x: README (0.05, 0.05, 0.091)
]
# README "Gear ratios", "Motor inertias", "Friction" (Coulomb = coulomb_pos = coulomb_neg, viscous).
GEAR_RATIO = [245.0, 245.0, 245.0, 142.0, 180.0, 128.0]
MOTOR_INERTIA = [6.0e-3, 6.0e-3, 6.0e-3, 1.5e-3, 1.5e-3, 1.0e-3]
COULOMB = [1.00, 1.10, 1.60, 0.45, 0.50, 0.50]
VISCOUS = [3e-3, 3e-3, 3e-3, 1e-3, 1e-3, 1e-3]
# README "Axis-2 gravity balancing": torsion spring on joint 2, N m/rad and rad.
BALANCE_STIFFNESS = 4200.0
BALANCE_SPRINGREF = 0.0

# World position of each MJCF body link1..link6 at zero joint angles: the sums of the bodies' pos
# in robots/irb6700/irb6700.xml. No body there is rotated, so at zero every body frame has the
# world's axes.
BODY_ORIGIN_AT_ZERO = [
    (0, 0, 0.78),
    (0.32, 0, 0.78),
    (0.32, 0, 1.905),
    (0.32, 0, 2.105),
    (1.4625, 0, 2.105),
    (1.6625, 0, 2.105),
]


def irb6700() -> rtb.DHRobot:
    """The arm in standard DH (the kinematics of tests/test_irb6700.py) with the README's dynamics.

    Each MJCF body ``link{i}`` and DH link frame i are fixed to the same link, so the transform
    between them is constant; it is taken at zero joint angles (DH offsets included), where the
    body frame has the world's axes at ``BODY_ORIGIN_AT_ZERO`` and the DH frame is the toolbox's
    ``fkine_all``: ``R = R_dh^T``, body origin ``R (o_body - o_dh)`` in the DH frame. Then
    ``r = R (o_body - o_dh) + R c`` and ``I = R I_body R^T``. Friction: ``B`` = viscous and
    ``Tc`` = (+Coulomb, -Coulomb), both motor side, as the toolbox expects.
    """
    robot = rtb.DHRobot(
        [
            rtb.RevoluteDH(d=0.78, a=0.32, alpha=-PI / 2),
            rtb.RevoluteDH(a=1.125, offset=-PI / 2),
            rtb.RevoluteDH(a=0.2, alpha=-PI / 2),
            rtb.RevoluteDH(d=1.1425, alpha=PI / 2),
            rtb.RevoluteDH(alpha=-PI / 2),
            rtb.RevoluteDH(d=0.2),
        ],
        name="irb6700-like (README dynamics)",
    )
    frames = robot.fkine_all(np.zeros(robot.n))  # frames[0] is the base
    for i, link in enumerate(robot.links):
        R = frames[i + 1].R.T  # world axes (= body axes at zero) in DH frame i
        origin = R @ (np.array(BODY_ORIGIN_AT_ZERO[i]) - frames[i + 1].t)
        link.m = MASS[i]
        link.r = origin + R @ np.array(COM[i], dtype=float)
        link.I = R @ np.diag(INERTIA[i]) @ R.T
        link.Jm = MOTOR_INERTIA[i]
        link.G = GEAR_RATIO[i]
        link.B = VISCOUS[i]
        link.Tc = [COULOMB[i], -COULOMB[i]]
    return robot


def irb6700_balance_torque(q: np.ndarray) -> np.ndarray:
    """Arm-side torque the axis-2 drive supplies against the balancing spring, shape (n, 6).

    The spring applies ``-k (q2 - springref)`` to joint 2 (MuJoCo's joint stiffness); the drive
    holds it with ``+k (q2 - springref)``, zero on the other axes. ``rne(q, qd, qdd)`` plus this
    is the arm-side torque the motors must supply (rigid gearbox, Stribeck excess aside).
    """
    q = np.atleast_2d(q)
    tau = np.zeros_like(q, dtype=float)
    tau[:, 1] = BALANCE_STIFFNESS * (q[:, 1] - BALANCE_SPRINGREF)
    return tau
