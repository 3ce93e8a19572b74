// Two spur gear sectors in mesh (schemas/examples/gear-pair.json), plane strain, mm: module 2,
// pressure angle 20 degrees, standard involute teeth (addendum 1 m, dedendum 1.25 m, no
// backlash), the driver z1 = 20 (centre at the origin, pitch radius 20), the driven z2 = 30
// (centre at (50, 0), pitch radius 30). Each sector holds 3 teeth and a rim down to its hub (the
// inner arc, radius 12 and 22), which the scene turns. Drawn at the first mesh position: the
// driver turned by -12 degrees from the position where its middle tooth's axis lies on the line
// of centres (its leading flank touches at the pitch point half a tooth's thickness, 4.5
// degrees, before that), the driven by +8 degrees (-12 z1 / z2) plus a preload angle `preload`, which presses
// the meshing flanks together (the transmitted load). The driven teeth are the three that the
// driver's leading (counter-clockwise) flanks push while the driver turns counter-clockwise.
// Mesh it with
//   gmsh gear-pair.geo -2 -order 2 -format msh41 -o gear-pair.msh   (or grip mesh gear-pair.geo --order 2)
// Physical surfaces: driver, driven. Physical curves: driver_hub, driven_hub (the turned arcs),
// driver_flanks, driven_flanks (the involute flanks that mesh: each body's contact_set).
m = 2;                 // module
alpha = 20 * Pi / 180; // pressure angle
lc_flank = 0.5;        // element size on the meshing flanks
lc_rim = 2.5;          // element size at the hubs
preload = 5e-4;        // the driven gear's extra angle (rad) into the mesh
np = 8;                // points on each involute

// Gear: teeth of a gear with z teeth, centre (cx, cy), its tooth k at angle phi0 + k 2 pi / z
// (k = 0 .. nt - 1), a sector from half a pitch before the first tooth to half a pitch after
// the last, down to the hub radius ri. Adds its surface to `surf`, its hub arc to `hub`, its
// counter-clockwise flanks to `flank`.
Macro Gear
  r = m * z / 2;  rb = r * Cos(alpha);  ra = r + m;  rf = r - 1.25 * m;
  half = Pi / (2 * z) + Tan(alpha) - alpha;  // the flank's angle from the tooth's axis at rb
  pitch = 2 * Pi / z;
  c0 = newp; Point(c0) = {cx, cy, 0};
  s0 = phi0 - pitch / 2;  s1 = phi0 + (nt - 0.5) * pitch;
  h0 = newp; Point(h0) = {cx + ri * Cos(s0), cy + ri * Sin(s0), 0, lc_rim};
  h1 = newp; Point(h1) = {cx + ri * Cos(s1), cy + ri * Sin(s1), 0, lc_rim};
  f0 = newp; Point(f0) = {cx + rf * Cos(s0), cy + rf * Sin(s0), 0, lc_flank * 2};
  loop[] = {};
  l = newc; Line(l) = {h0, f0}; loop[] += {l};
  last = f0;
  For k In {0 : nt - 1}
    phi = phi0 + k * pitch;
    // The root (rf) and base (rb) points of the two flanks, the involutes rb -> ra.
    a = newp; Point(a) = {cx + rf * Cos(phi - half), cy + rf * Sin(phi - half), 0, lc_flank * 2};
    b = newp; Point(b) = {cx + rb * Cos(phi - half), cy + rb * Sin(phi - half), 0, lc_flank};
    l = newc; Circle(l) = {last, c0, a}; loop[] += {l};
    l = newc; Line(l) = {a, b}; loop[] += {l};
    minus[] = {b};
    plus[] = {};
    For i In {1 : np}
      rr = rb + (ra - rb) * i / np;
      ar = Acos(rb / rr);
      th = half - (Tan(ar) - ar);
      q = newp; Point(q) = {cx + rr * Cos(phi - th), cy + rr * Sin(phi - th), 0, lc_flank};
      minus[] += {q};
      q = newp; Point(q) = {cx + rr * Cos(phi + th), cy + rr * Sin(phi + th), 0, lc_flank};
      plus[] = {q, plus[]};
    EndFor
    bp = newp; Point(bp) = {cx + rb * Cos(phi + half), cy + rb * Sin(phi + half), 0, lc_flank};
    plus[] += {bp};
    l = newc; Spline(l) = minus[]; loop[] += {l};
    l = newc; Circle(l) = {minus[np], c0, plus[0]}; loop[] += {l};
    l = newc; Spline(l) = plus[]; loop[] += {l}; flank[] += {l};
    ap = newp; Point(ap) = {cx + rf * Cos(phi + half), cy + rf * Sin(phi + half), 0, lc_flank * 2};
    l = newc; Line(l) = {bp, ap}; loop[] += {l};
    last = ap;
  EndFor
  f1 = newp; Point(f1) = {cx + rf * Cos(s1), cy + rf * Sin(s1), 0, lc_flank * 2};
  l = newc; Circle(l) = {last, c0, f1}; loop[] += {l};
  l = newc; Line(l) = {f1, h1}; loop[] += {l};
  // The hub arc, in two halves (a gmsh arc spans less than pi).
  hm = newp; Point(hm) = {cx + ri * Cos((s0 + s1) / 2), cy + ri * Sin((s0 + s1) / 2), 0, lc_rim};
  l = newc; Circle(l) = {h1, c0, hm}; loop[] += {l}; hub[] += {l};
  l = newc; Circle(l) = {hm, c0, h0}; loop[] += {l}; hub[] += {l};
  cl = newll; Curve Loop(cl) = loop[];
  surf = news; Plane Surface(surf) = {cl};
Return

flank[] = {}; hub[] = {};
z = 20; cx = 0; cy = 0; ri = 12; nt = 3; phi0 = (-12 - 18) * Pi / 180;
Call Gear;
driver = surf; driver_flank[] = flank[]; driver_hub[] = hub[];
flank[] = {}; hub[] = {};
z = 30; cx = 50; cy = 0; ri = 22; nt = 3; phi0 = Pi + (8 - 30) * Pi / 180 + preload;
Call Gear;
driven = surf; driven_flank[] = flank[]; driven_hub[] = hub[];

Physical Surface("driver") = {driver};
Physical Surface("driven") = {driven};
Physical Curve("driver_hub") = {driver_hub[]};
Physical Curve("driven_hub") = {driven_hub[]};
Physical Curve("driver_flanks") = {driver_flank[]};
Physical Curve("driven_flanks") = {driven_flank[]};
