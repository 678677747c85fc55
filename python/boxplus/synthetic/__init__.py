"""Synthetic data with known truth: the one home of boxplus' generators.

Every generator here is seeded, returns its ground truth beside the data, and
draws its noise through the core noise vocabulary (:mod:`boxplus.noise`), so
that defaults can be chosen and σ checked on *families* of generated problems
rather than on a handful of files. Data that a tool reads from disk are
written in the same formats users bring (g2o files, image folders, IMU CSV).

Generators live in one module per kind of data; they are imported by name
(``from boxplus.synthetic import <module>``) so that importing this package
costs nothing.
"""
