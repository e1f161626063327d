import numpy as np

from training.mocap.rotations import (euler_matrix, matrix_to_euler_zyx, matrix_to_quat, quat_slerp, quat_to_matrix,
                                rotation_between)

rng = np.random.default_rng(0)


def random_rotations(n):
    return euler_matrix(rng.uniform(-np.pi, np.pi, (n, 3)), "zyx", intrinsic=True)


def test_quaternion_round_trip_covers_all_angles():
    m = random_rotations(500)
    back = quat_to_matrix(matrix_to_quat(m))
    assert np.abs(back - m).max() < 1e-9


def test_intrinsic_and_extrinsic_orders_are_reverses():
    a = rng.uniform(-1, 1, (20, 3))
    assert np.allclose(euler_matrix(a, "xyz", intrinsic=False), euler_matrix(a[:, ::-1], "zyx", intrinsic=True))


def test_zyx_decomposition_inverts_composition():
    angles = rng.uniform(-1.4, 1.4, (100, 3))  # away from gimbal lock
    m = euler_matrix(angles, "zyx", intrinsic=True)
    assert np.allclose(matrix_to_euler_zyx(m), angles)


def test_known_rotation_about_y_turns_z_into_x():
    # Heading pi/2 faces +x: a quarter turn about +y takes +z to +x.
    m = euler_matrix(np.array([np.pi / 2]), "y", intrinsic=True)
    assert np.allclose(m @ [0, 0, 1], [1, 0, 0])


def test_slerp_endpoints_and_midpoint():
    q = matrix_to_quat(random_rotations(2))
    assert np.allclose(np.abs(np.sum(quat_slerp(q[0], q[1], 0.0) * q[0])), 1)
    assert np.allclose(np.abs(np.sum(quat_slerp(q[0], q[1], 1.0) * q[1])), 1)
    mid = quat_to_matrix(quat_slerp(q[0], q[1], 0.5))
    m0, m1 = quat_to_matrix(q[0]), quat_to_matrix(q[1])
    # The midpoint is equally far (in angle) from both ends.
    angle = lambda a, b: np.arccos(np.clip((np.trace(a.T @ b) - 1) / 2, -1, 1))
    assert abs(angle(m0, mid) - angle(mid, m1)) < 1e-9


def test_rotation_between_maps_directions_including_opposites():
    for a, b in [([0, 1, 0], [1, 0, 0]), ([0, 0, 1], [0, 0, -1]), ([1, 2, 3], [-3, 1, 0.5])]:
        r = rotation_between(np.array(a, float), np.array(b, float))
        assert np.allclose(r @ (np.array(a) / np.linalg.norm(a)), np.array(b) / np.linalg.norm(b))
        assert np.allclose(r @ r.T, np.eye(3))
