"""Synthetic data with known truth: the one home of boxplus' generators.

Every generator here is seeded, returns its ground truth beside the data, and
draws its noise through the core noise vocabulary (:mod:`boxplus.noise`), so
that defaults can be chosen and σ checked on *families* of generated problems
rather than on a handful of files. Data that a tool reads from disk are
written in the same formats users bring (g2o files, image folders, IMU CSV).

Generators live in one module per kind of data; they are imported by name
(``from boxplus.synthetic import <module>``) so that importing this package
costs nothing:

* :mod:`~boxplus.synthetic.pose_graphs`: g2o pose graphs of every family, with
  wrong loop closures on request, and their truth (``python -m
  boxplus.synthetic.pose_graphs`` writes them);
* :mod:`~boxplus.synthetic.trajectories`: the families' true trajectories;
  :mod:`~boxplus.synthetic.se_arrays`: SE(2)/SE(3) arithmetic on arrays of poses;
* :mod:`~boxplus.synthetic.cameras`: board views of a camera with OpenCV-model
  lens and pixel noise;
* :mod:`~boxplus.synthetic.joint_rigs`: a robot with a stereo pair and laser
  sensors like Le & Ng's (Sec. VIII–XI), with its true DH table and extrinsics;
* :mod:`~boxplus.synthetic.camera_imu`: a camera and an IMU waved in front of
  a target (time offset, biases, bias drift);
* :mod:`~boxplus.synthetic.images`: images rendered through any lens model
  (chessboard, ChArUco, AprilTag targets).
"""
