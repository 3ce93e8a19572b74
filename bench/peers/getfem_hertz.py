#!/usr/bin/python3
"""GetFEM on grip's Hertz geometry (bench/peers/run.sh): the half-disc of
schemas/examples/hertz.json (R 10 mm, E 200 GPa, nu 0.3, plane strain, small strain) with
its diameter lowered 0.05 mm in 10 equal steps and held in x at the centre, against a rigid
flat with friction MU, by GetFEM's integral contact brick with a rigid obstacle (augmented
Lagrangian, Alart-Curnier, Newton). The mesh is grip's (MESH.json: reference node positions
and counter-clockwise quadrilaterals, written by compare.py from grip's result on the same
scene), with Q1 or Q2 elements; SIZE (the element size near the pole) sets the augmentation.

Prints one JSON line: P (N/mm), a and p0 from a semi-ellipse fitted to the contact pressure
at the contact boundary's nodes, their closed-form values at that P, and the seconds.
Usage: getfem_hertz.py MU SIZE DEGREE MESH.json [--profile]
"""
import json
import math
import sys
import time

import numpy as np

import getfem as gf

gf.util("trace level", 0)

START = time.monotonic()
MU, SIZE, DEGREE, MESH = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
R, E, NU, DEPTH, STEPS, EXTENT = 10.0, 200000.0, 0.3, 0.05, 10, 0.8

with open(MESH) as f:
    grip_mesh = json.load(f)
nodes = np.array(grip_mesh["nodes"])
mesh = gf.Mesh("empty", 2)
gt = gf.GeoTrans("GT_QK(2,1)")
for cell in grip_mesh["cells"]:
    # GetFEM's QK(2,1) node order: (0,0), (1,0), (0,1), (1,1); grip's: counter-clockwise.
    mesh.add_convex(gt, nodes[[cell[0], cell[1], cell[3], cell[2]]].T)

# Boundary regions: the arc faces within EXTENT of the pole (contact), the diameter (y = 0).
border = mesh.outer_faces()
CONTACT, DIAMETER = 1, 2
faces_contact, faces_diameter = [], []
for (cv, f) in border.T:
    fp = mesh.pid_in_faces(np.array([[cv], [f]]))
    xy = mesh.pts(fp)
    if np.all(np.abs(xy[1]) < 1e-9):
        faces_diameter.append((cv, f))
    elif np.all(np.abs(np.arcsin(np.clip(xy[0] / R, -1, 1))) * R <= EXTENT * (1 + 1e-9)) and np.all(xy[1] < 0):
        faces_contact.append((cv, f))
mesh.set_region(CONTACT, np.array(faces_contact).T)
mesh.set_region(DIAMETER, np.array(faces_diameter).T)

mfu = gf.MeshFem(mesh, 2)
mfu.set_classical_fem(DEGREE)
mfd = gf.MeshFem(mesh, 1)
mfd.set_classical_fem(DEGREE)
mflambda = gf.MeshFem(mesh, 2)
mflambda.set_classical_fem(DEGREE)  # on the contact boundary only (reduced below)
mim = gf.MeshIm(mesh, gf.Integ("IM_GAUSS_PARALLELEPIPED(2,%d)" % (2 * DEGREE + 2)))

md = gf.Model("real")
md.add_fem_variable("u", mfu)
lam_pstrain = E * NU / ((1 + NU) * (1 - 2 * NU))
mu_lame = E / (2 * (1 + NU))
md.add_initialized_data("lambda_l", [lam_pstrain])
md.add_initialized_data("mu_l", [mu_lame])
md.add_isotropic_linearized_elasticity_brick(mim, "u", "lambda_l", "mu_l")
# The diameter: u_y prescribed (with multipliers), the centre node held in x.
md.add_initialized_data("dir_y", [0.0, 1.0])
md.add_initialized_fem_data("uy_value", mfd, np.zeros(mfd.nbdof()))
md.add_filtered_fem_variable("mult_y", mfd, DIAMETER)
md.add_linear_term(mim, "mult_y*(u(2) - uy_value)", DIAMETER)
md.add_initialized_data("centre", [0.0, 0.0])
md.add_initialized_data("ex", [1.0, 0.0])
md.add_pointwise_constraints_with_multipliers("u", "centre", "ex")
# The flat y = -R: signed distance y + R (positive outside the obstacle).
md.add_initialized_fem_data("obstacle", mfd, mfd.eval("y + %g" % R))
md.add_filtered_fem_variable("lambda_c", mflambda, CONTACT)
md.add_initialized_data("r_aug", [E / SIZE])
md.add_initialized_data("friction", [MU])
md.add_initialized_data("alpha", [1.0])
md.add_initialized_fem_data("wt", mfu, np.zeros(mfu.nbdof()))
md.add_integral_contact_with_rigid_obstacle_brick(mim, "u", "lambda_c", "obstacle", "r_aug", "friction",
                                                  CONTACT, 1, "alpha", "wt")

for step in range(1, STEPS + 1):
    md.set_variable("uy_value", -DEPTH * step / STEPS * np.ones(mfd.nbdof()))
    md.set_variable("wt", md.variable("u"))  # the slip is measured from the last step
    md.solve("max_res", 1e-9, "max_iter", 100, "lsearch", "simplest")

# The load P per unit thickness, and the contact pressure at the contact boundary's nodes
# (the multiplier interpolated there).
P = abs(gf.asm_generic(mim, 0, "lambda_c(2)", CONTACT, md))
dofs = mflambda.basic_dof_on_region(CONTACT)
full = np.zeros(mflambda.nbdof())
full[dofs] = md.variable("lambda_c")
xs = np.unique(np.round(mflambda.basic_dof_nodes(dofs)[0], 12))
pts = np.array([xs, -np.sqrt(np.maximum(R * R - xs * xs, 0.0))])
ly = gf.compute_interpolate_on(mflambda, full, pts)[1]
# Pressure has the sign of the load: the nodes that press. (The multiplier has the degree of
# u, so it oscillates a little beyond the zone's edge: nodes under 2 % of the peak are out.)
sigma_n = ly * np.sign(np.sum(ly))
if "--profile" in sys.argv:
    for x, s in zip(xs, ly):
        print("%9.4f %12.3f" % (x, s), file=sys.stderr)
Es = E / (1 - NU * NU)
a_closed = math.sqrt(4 * P * R / (math.pi * Es))
p0_closed = 2 * P / (math.pi * a_closed)
touch = sigma_n > 0.02 * sigma_n.max()
X, Y = pts[0][touch] ** 2, sigma_n[touch] ** 2
n = len(X)
slope = (n * np.sum(X * Y) - np.sum(X) * np.sum(Y)) / (n * np.sum(X * X) - np.sum(X) ** 2)
intercept = (np.sum(Y) - slope * np.sum(X)) / n
a_fit, p0_fit = math.sqrt(-intercept / slope), math.sqrt(intercept)
print(json.dumps({"peer": "getfem", "mu": MU, "size": SIZE, "degree": DEGREE, "dofs": int(mfu.nbdof()),
                  "P": P, "a": a_closed, "p0": p0_closed, "a_fit": a_fit, "p0_fit": p0_fit,
                  "a_error": a_fit / a_closed - 1, "p0_error": p0_fit / p0_closed - 1,
                  "seconds_inside": time.monotonic() - START}))
