// Boussinesq's flat punch, axisymmetric (schemas/examples/flat-punch-axisymmetric.json): the
// section r >= 0, z <= 0 of a body 1000 punch radii deep and wide (a quarter disc round the
// punch's centre, R = 1000 mm, a = 1 mm), meshed by gmsh into 6-node triangles of 0.01 mm
// within 0.05 mm of the punch's edge (r = a on the surface), growing to 80 mm. Mesh it with
//   gmsh flat-punch-axisymmetric.geo -2 -order 2 -format msh41 -o flat-punch-axisymmetric.msh
// Physical curves: "surface" (0 <= r <= 3 a, the contact candidates), "axis", "far" (the arc);
// physical surface "body".
R = 1000;
a = 1;
Point(1) = {0, 0, 0};
Point(2) = {a, 0, 0};
Point(3) = {3 * a, 0, 0};
Point(4) = {R, 0, 0};
Point(5) = {0, -R, 0};
Line(1) = {1, 5};      // the axis, downward
Circle(2) = {5, 1, 4}; // the far arc
Line(3) = {4, 3};
Line(4) = {3, 2};
Line(5) = {2, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Field[1] = Distance;
Field[1].PointsList = {2};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.01;
Field[2].SizeMax = 80;
Field[2].DistMin = 0.05;
Field[2].DistMax = 400;
Field[3] = Distance;
Field[3].CurvesList = {4, 5};
Field[4] = Threshold;
Field[4].InField = 3;
Field[4].SizeMin = 0.04;
Field[4].SizeMax = 80;
Field[4].DistMin = 0.1;
Field[4].DistMax = 500;
Field[5] = Min;
Field[5].FieldsList = {2, 4};
Background Field = 5;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Physical Curve("surface") = {4, 5};
Physical Curve("axis") = {1};
Physical Curve("far") = {2};
Physical Surface("body") = {1};
