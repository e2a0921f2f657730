"""The 24 SMPL joints on the MakeHuman `game_engine` rig, the merged skinning weights, and the
linear map that re-poses the A-posed base mesh into SMPL's T-pose.

Every joint is the head of one rig bone, and every head is the mean of a `joint-*` helper cube in
`base.obj` (the rig's "CUBE" strategy), so joints are linear in the mesh vertices. Re-posing with
linear blend skinning under *fixed* rotations is then linear in the rest vertices too: the same
map applies exactly to the mean body and to every macro target offset.
"""

import numpy as np

JOINT_NAMES = [
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2",
    "left_ankle", "right_ankle", "spine3", "left_foot", "right_foot", "neck", "left_collar",
    "right_collar", "head", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow",
    "left_wrist", "right_wrist", "left_hand", "right_hand",
]  # fmt: skip
PARENTS = [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21]

# The rig bone whose head is each SMPL joint (DESIGN.md, "The embedded default body").
JOINT_BONES = [
    "pelvis", "thigh_l", "thigh_r", "spine_01", "calf_l", "calf_r", "spine_02", "foot_l",
    "foot_r", "spine_03", "ball_l", "ball_r", "neck_01", "clavicle_l", "clavicle_r", "head",
    "upperarm_l", "upperarm_r", "lowerarm_l", "lowerarm_r", "hand_l", "hand_r", "middle_01_l",
    "middle_01_r",
]  # fmt: skip
FINGERS = ("thumb", "index", "middle", "ring", "pinky")


def bone_joint(bone):
    """The SMPL joint a rig bone's skinning weights merge into."""
    if bone in JOINT_BONES:
        return JOINT_BONES.index(bone)
    if bone == "Root":
        return 0
    if bone.startswith(FINGERS):
        return 22 if bone.endswith("_l") else 23
    raise SystemExit(f"rig bone {bone!r} has no SMPL joint to merge into")


def joint_cube_matrix(base, rig):
    """(24, N) matrix whose rows average each joint's helper cube (the rig's bone heads)."""
    out = np.zeros((24, len(base.vertices)))
    for j, bone in enumerate(JOINT_BONES):
        head = rig[bone]["head"]
        if head.get("strategy") != "CUBE":
            raise SystemExit(f"rig bone {bone}: expected a CUBE head, found {head.get('strategy')}")
        idx = base.group_vertices(head["cube_name"])
        out[j, idx] = 1.0 / len(idx)
    return out


def merged_weights(weights_json, num_vertices):
    """(N, 24) skinning weights: each rig bone's weights added onto its SMPL joint, rows
    normalised to sum to 1."""
    w = np.zeros((num_vertices, 24))
    for bone, pairs in weights_json["weights"].items():
        if not pairs:
            continue
        pairs = np.asarray(pairs)
        np.add.at(w[:, bone_joint(bone)], pairs[:, 0].astype(np.int64), pairs[:, 1])
    sums = w.sum(1)
    if np.any(sums <= 0):
        raise SystemExit(f"{np.count_nonzero(sums <= 0)} vertices have no skinning weight")
    return w / sums[:, None]


def _frame(direction, secondary):
    """Orthonormal frame (columns) with first axis `direction`, second axis towards `secondary`."""
    a = direction / np.linalg.norm(direction)
    b = secondary - a * (a @ secondary)
    b /= np.linalg.norm(b)
    return np.stack([a, b, np.cross(a, b)], axis=1)


def _align(direction, secondary, to_direction, to_secondary):
    """The rotation taking `direction` onto `to_direction` and `secondary` towards `to_secondary`."""
    return _frame(to_direction, to_secondary) @ _frame(direction, secondary).T


def tpose_rotations(joints, rig_heads):
    """World rotations (24, 3, 3) that bring the A-posed arms into SMPL's T-pose.

    Upper arm, forearm and hand point along +X (left) / -X (right). The elbow's hinge (normal of
    the upper-arm/forearm plane) becomes -Y on the left and +Y on the right, so that flexing the
    elbow about SMPL's Y axis moves the forearm forward, as it does on SMPL. The hand's knuckle
    line (pinky to index) points forward (+Z): palms face down, thumbs forward, as on SMPL.
    Everything else keeps its rest orientation (local identity), legs included.
    """
    rot = np.tile(np.eye(3), (24, 1, 1))
    for side, sign in (("l", 1.0), ("r", -1.0)):
        shoulder, elbow, wrist, hand = (
            (16, 18, 20, 22) if side == "l" else (17, 19, 21, 23)
        )
        upper = joints[elbow] - joints[shoulder]
        fore = joints[wrist] - joints[elbow]
        hinge = np.cross(upper, fore)
        along = np.array([sign, 0.0, 0.0])
        hinge_to = np.array([0.0, -sign, 0.0])
        rot[shoulder] = _align(upper, hinge, along, hinge_to)
        rot[elbow] = _align(fore, hinge, along, hinge_to)
        knuckles = rig_heads[f"index_01_{side}"] - rig_heads[f"pinky_01_{side}"]
        rot[wrist] = _align(joints[hand] - joints[wrist], knuckles, along, np.array([0.0, 0.0, 1.0]))
        rot[hand] = rot[wrist]
    return rot


def forward_kinematics(joints, world_rot):
    """Posed joints for rest joints (..., 24, 3) under world rotations (24, 3, 3)."""
    posed = np.empty_like(joints)
    for j, p in enumerate(PARENTS):
        if p < 0:
            posed[..., j, :] = joints[..., j, :]
        else:
            posed[..., j, :] = posed[..., p, :] + (joints[..., j, :] - joints[..., p, :]) @ world_rot[p].T
    return posed


def lbs(vertices, joints, weights, world_rot):
    """Linear blend skinning of rest vertices (..., V, 3) with rest joints (..., 24, 3):
    v' = sum_k w_k (R_k (v - J_k) + J'_k). Linear in (vertices, joints) jointly."""
    posed_joints = forward_kinematics(joints, world_rot)
    out = np.zeros_like(vertices)
    for k in range(24):
        wk = weights[:, k]
        nz = wk > 0
        if not np.any(nz):
            continue
        local = (vertices[..., nz, :] - joints[..., k : k + 1, :]) @ world_rot[k].T
        out[..., nz, :] += wk[nz, None] * (local + posed_joints[..., k : k + 1, :])
    return out, posed_joints
