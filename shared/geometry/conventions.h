#pragma once
// Conventions used everywhere in silnet. State them once, keep to them.
//
// World frame    metres, right-handed, Z up, the floor is Z = 0.
// Camera frame   x right, y down, z forward (OpenCV). A camera's pose is cam_from_world:
//                x_cam = R * X + t, so its centre is C = -R^T t.
// Pixels         (u, v) with u to the right, v down; integer coordinates are pixel centres,
//                so pixel (0, 0) covers [-0.5, 0.5]^2 and the image covers
//                [-0.5, width - 0.5] x [-0.5, height - 0.5].
// Intrinsics     K = [fx s cx; 0 fy cy; 0 0 1]; distortion in OpenCV's order
//                (k1, k2, p1, p2, k3) applied to normalised coordinates.
// Epipolar       F_ij maps pixels of camera i to lines in camera j: x_j^T F_ij x_i = 0, on
//                undistorted pixels. e_i (F e_i = 0) is camera j's centre seen in i.
// Time           a camera has a constant frame rate fps and an offset o in frames: its frame
//                k is exposed at reference time (k + o) / fps seconds. With equal rates, frame
//                k of camera i is simultaneous with frame k + (o_i - o_j) of camera j: the
//                pair offset is o_i - o_j.
// Angles         radians in code, degrees only in reports and command-line options.
