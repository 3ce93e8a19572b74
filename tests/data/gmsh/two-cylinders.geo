// Two half-cylinders in one file, each a physical surface (tests/verification/gmsh_scene_test.cpp):
// "upper" (centre (0, 10)) and "lower" (centre (0, -10)), R = 10 mm, touching at the origin;
// 6-node triangles of 0.05 mm within 1.2 mm of the contact point, growing to 1.5 mm.
//   gmsh two-cylinders.geo -2 -order 2 -format msh41 -o two-cylinders.msh
// Physical curves per body: <body>_contact (the arc within 1.5 mm of the pole), <body>_diameter.
R = 10;
theta = 1.5 / R;
// upper: centre (0, 10), the arc below its diameter
Point(1) = {0, R, 0};
Point(2) = {R, R, 0};
Point(3) = {R * Sin(theta), R - R * Cos(theta), 0};
Point(4) = {0, 0, 0};
Point(5) = {-R * Sin(theta), R - R * Cos(theta), 0};
Point(6) = {-R, R, 0};
Circle(1) = {6, 1, 5};
Circle(2) = {5, 1, 4};
Circle(3) = {4, 1, 3};
Circle(4) = {3, 1, 2};
Line(5) = {2, 6};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
// lower: centre (0, -10), the arc above its diameter (its own pole point, not shared)
Point(11) = {0, -R, 0};
Point(12) = {-R, -R, 0};
Point(13) = {-R * Sin(theta), -R + R * Cos(theta), 0};
Point(14) = {0, 0, 0};
Point(15) = {R * Sin(theta), -R + R * Cos(theta), 0};
Point(16) = {R, -R, 0};
Circle(11) = {16, 11, 15};
Circle(12) = {15, 11, 14};
Circle(13) = {14, 11, 13};
Circle(14) = {13, 11, 12};
Line(15) = {12, 16};
Curve Loop(11) = {11, 12, 13, 14, 15};
Plane Surface(11) = {11};
Field[1] = Distance;
Field[1].PointsList = {4, 14};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.05;
Field[2].SizeMax = 1.5;
Field[2].DistMin = 1.2;
Field[2].DistMax = 6;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Physical Curve("upper_contact") = {2, 3};
Physical Curve("upper_diameter") = {5};
Physical Curve("lower_contact") = {12, 13};
Physical Curve("lower_diameter") = {15};
Physical Surface("upper") = {1};
Physical Surface("lower") = {11};
