#!/usr/bin/python3
"""GetFEM on grip's strip on a cylinder (bench/peers/strip.py): the strip of
schemas/examples/strip-on-cylinder.json (L 1, t 0.02, Saint Venant-Kirchhoff E 1.5e6, nu 0,
plane strain, clamped at x = 0, end traction (0, -500) at x = 1 in 20 equal steps) on NX x NY
Q2 elements (9-node Lagrange, as grip's q9), wrapped onto the rigid cylinder of radius 0.4
centred at (0, -0.41) with friction 0.3, by GetFEM's large-sliding contact brick with a rigid
obstacle (augmented Lagrangian, raytracing, Newton on displacements and multipliers).

Prints one JSON line: the tip's displacement (the node at (1, 0)), unknowns, Newton
iterations, and the seconds inside (after the import) and of the 20 steps alone.
Usage: getfem_strip.py NX NY
"""
import json
import sys
import time

import numpy as np

START = time.monotonic()
import getfem as gf  # noqa: E402  (its import is part of the whole process, timed outside)

gf.util("trace level", 0)

NX, NY = int(sys.argv[1]), int(sys.argv[2])
L, T, E, NU, LOAD, STEPS, MU = 1.0, 0.02, 1.5e6, 0.0, 500.0, 20, 0.3

mesh = gf.Mesh("cartesian", np.linspace(0, L, NX + 1), np.linspace(0, T, NY + 1))
LEFT, RIGHT, BOTTOM = 1, 2, 3
border = mesh.outer_faces()
normals = mesh.normal_of_faces(border)
mesh.set_region(LEFT, border[:, normals[0] < -0.5])
mesh.set_region(RIGHT, border[:, normals[0] > 0.5])
mesh.set_region(BOTTOM, border[:, normals[1] < -0.5])

mfu = gf.MeshFem(mesh, 2)
mfu.set_classical_fem(2)
mflambda = gf.MeshFem(mesh, 2)
mflambda.set_classical_fem(2)
mim = gf.MeshIm(mesh, gf.Integ("IM_GAUSS_PARALLELEPIPED(2,6)"))
mim_contact = gf.MeshIm(mesh, gf.Integ("IM_GAUSS_PARALLELEPIPED(2,6)"))

md = gf.Model("real")
md.add_fem_variable("u", mfu)
lame_lambda, lame_mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
md.add_initialized_data("params", [lame_lambda, lame_mu])
md.add_finite_strain_elasticity_brick(mim, "SaintVenant Kirchhoff", "u", "params")
md.add_Dirichlet_condition_with_multipliers(mim, "u", 2, LEFT)
md.add_initialized_data("traction", [0.0, 0.0])
md.add_source_term_brick(mim, "u", "traction", RIGHT)

md.add_filtered_fem_variable("lambda", mflambda, BOTTOM)
md.add_initialized_data("r", [E / (L / NX)])
md.add_initialized_data("f", [MU])
md.add_initialized_data("alpha", [1.0])
contact = md.add_integral_large_sliding_contact_brick_raytracing("r", 0.1, "f", "alpha", 0)
md.add_rigid_obstacle_to_large_sliding_contact_brick(contact, "sqrt(X(1)*X(1) + (X(2)+0.41)*(X(2)+0.41)) - 0.4", 2)
md.add_slave_contact_boundary_to_large_sliding_contact_brick(contact, mim_contact, BOTTOM, "u", "lambda")

iterations = 0
steps_start = time.monotonic()
for step in range(1, STEPS + 1):
    md.set_variable("traction", [0.0, -LOAD * step / STEPS])
    out = md.solve("max_res", 1e-8, "max_iter", 100, "lsearch", "simplest", "alpha max ratio", 1.5,
                   "alpha min", 0.2, "alpha mult", 0.6)
    iterations += int(out[0])
steps_seconds = time.monotonic() - steps_start

u = md.variable("u")
tip_dofs = mfu.basic_dof_on_region(RIGHT)
nodes = mfu.basic_dof_nodes(tip_dofs)
at = [d for d, x, y in zip(tip_dofs, nodes[0], nodes[1]) if abs(x - L) < 1e-12 and abs(y) < 1e-12]
print(json.dumps({"peer": "getfem", "mesh": [NX, NY], "dofs": int(mfu.nbdof()),
                  "tip": [float(u[at[0]]), float(u[at[1]])], "newton_iterations": iterations,
                  "seconds_steps": steps_seconds, "seconds_inside": time.monotonic() - START}))
