// A hub pressed onto a hollow shaft (schemas/examples/press-fit.json), plane strain, mm. The
// shaft's outer radius is 10 + 0.01, the hub's bore 10: a radial interference of 0.01 mm that the
// first stage closes. Shaft: bore radius 5 (held), hub: outer radius 20 (its rim, turned in the
// second stage). Structured quadrilaterals, second order (9-node: q9), 12 elements per quarter
// round, matching on the two sides of the interface. Mesh it with
//   gmsh press-fit.geo -2 -order 2 -format msh41 -o press-fit.msh     (or grip mesh press-fit.geo --order 2)
// Physical surfaces: shaft, hub. Physical curves: shaft_bore, hub_rim (the held and the turned
// circle), shaft_surface and hub_bore (the whole interface, each body's contact_set), and their
// halves shaft_upper, shaft_lower, hub_upper, hub_lower (y >= 0, y <= 0): the scene pairs them
// half with half, since a contact pair of two closed rings does not converge in grip today.
c = 5;          // the shaft's bore
R = 10;         // the hub's bore: the nominal interface radius
delta = 0.01;   // the radial interference
b = 20;         // the hub's rim
n = 12;         // elements per quarter round
Point(1) = {0, 0, 0};
// Rings of points at radius rr, one per quarter (angles 0, 90, 180, 270 degrees).
For k In {0:3}
  Point(10 + k) = {c * Cos(k * Pi / 2), c * Sin(k * Pi / 2), 0};
  Point(20 + k) = {(R + delta) * Cos(k * Pi / 2), (R + delta) * Sin(k * Pi / 2), 0};
  Point(30 + k) = {R * Cos(k * Pi / 2), R * Sin(k * Pi / 2), 0};
  Point(40 + k) = {b * Cos(k * Pi / 2), b * Sin(k * Pi / 2), 0};
EndFor
For k In {0:3}
  k1 = (k + 1) % 4;
  Circle(10 + k) = {10 + k, 1, 10 + k1};
  Circle(20 + k) = {20 + k, 1, 20 + k1};
  Circle(30 + k) = {30 + k, 1, 30 + k1};
  Circle(40 + k) = {40 + k, 1, 40 + k1};
  Line(50 + k) = {10 + k, 20 + k};  // shaft, radial
  Line(60 + k) = {30 + k, 40 + k};  // hub, radial
EndFor
For k In {0:3}
  k1 = (k + 1) % 4;
  Curve Loop(100 + k) = {50 + k, 20 + k, -(50 + k1), -(10 + k)};
  Plane Surface(100 + k) = {100 + k};
  Curve Loop(200 + k) = {60 + k, 40 + k, -(60 + k1), -(30 + k)};
  Plane Surface(200 + k) = {200 + k};
EndFor
Transfinite Curve {10:13, 20:23, 30:33, 40:43} = n + 1;
Transfinite Curve {50:53} = 5 + 1;
Transfinite Curve {60:63} = 8 + 1 Using Progression 1.1;
Transfinite Surface {100:103, 200:203};
Recombine Surface {100:103, 200:203};
Physical Surface("shaft") = {100:103};
Physical Surface("hub") = {200:203};
Physical Curve("shaft_bore") = {10:13};
Physical Curve("shaft_surface") = {20:23};
Physical Curve("shaft_upper") = {20, 21};
Physical Curve("shaft_lower") = {22, 23};
Physical Curve("hub_bore") = {30:33};
Physical Curve("hub_upper") = {30, 31};
Physical Curve("hub_lower") = {32, 33};
Physical Curve("hub_rim") = {40:43};
