#!/usr/bin/python3
"""Writes the meshes of tests/hard/bulging_block_slow_test.cpp: the quarter [0, 1] x [0, 1] of a
2 x 2 block whose corner (1, 1) is rounded by a fillet of radius 0.1 (centre (0.9, 0.9)), in
9-node quadrilaterals (q9). Level 0: gmsh's quadrilaterals of about 0.25, 0.083 along the fillet;
levels 1 and 2 split every element of the level before into four (nested meshes, the new
boundary nodes on the arc), then second order. Physical curves: "surface" (the side x = 1, the
fillet and the top y = 1: the contact candidates), "left" (x = 0), "bottom" (y = 0); surface
"block". Run from anywhere (gmsh's Python module):
    /usr/bin/python3 tests/data/gmsh/bulging_block_fillet.py"""
import os

import gmsh

RADIUS, SIZE = 0.1, 0.25
HERE = os.path.dirname(os.path.abspath(__file__))


def write(level):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    g = gmsh.model.geo
    p = [g.addPoint(x, y, 0) for x, y in ((0, 0), (1, 0), (1, 1 - RADIUS), (1 - RADIUS, 1), (0, 1))]
    centre = g.addPoint(1 - RADIUS, 1 - RADIUS, 0)
    bottom, side = g.addLine(p[0], p[1]), g.addLine(p[1], p[2])
    arc = g.addCircleArc(p[2], centre, p[3])
    top, left = g.addLine(p[3], p[4]), g.addLine(p[4], p[0])
    surface = g.addPlaneSurface([g.addCurveLoop([bottom, side, arc, top, left])])
    g.synchronize()
    for dim, tags, name in ((1, [side, arc, top], "surface"), (1, [left], "left"), (1, [bottom], "bottom"),
                            (2, [surface], "block")):
        gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
    # Elements of SIZE / 3 within RADIUS / 2 of the fillet, growing to SIZE half a block away.
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "CurvesList", [arc])
    field.setNumber(distance, "NumPointsPerCurve", 100)
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", SIZE / 3)
    field.setNumber(threshold, "SizeMax", SIZE)
    field.setNumber(threshold, "DistMin", RADIUS / 2)
    field.setNumber(threshold, "DistMax", 0.5)
    field.setAsBackgroundMesh(threshold)
    for option, value in (("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.MeshSizeFromPoints", 0),
                          ("Mesh.MeshSizeFromCurvature", 0), ("Mesh.RecombineAll", 1), ("Mesh.Algorithm", 6),
                          ("Mesh.RecombinationAlgorithm", 1), ("Mesh.SecondOrderIncomplete", 0),
                          ("Mesh.MshFileVersion", 4.1)):
        gmsh.option.setNumber(option, value)
    gmsh.model.mesh.generate(2)
    for _ in range(level):
        gmsh.model.mesh.refine()
    gmsh.model.mesh.setOrder(2)
    gmsh.write(os.path.join(HERE, "bulging-block-fillet-%d.msh" % level))
    gmsh.finalize()


if __name__ == "__main__":
    for level in range(3):
        write(level)
