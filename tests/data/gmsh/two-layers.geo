// A block of two layers, one body of two materials (tests/verification/gmsh_scene_test.cpp):
// "soft" [0, 10] x [0, 5] under "stiff" [0, 10] x [5, 10], sharing the line y = 5; 10 x 10
// structured quadrilaterals. Physical curves: bottom, top; physical point: corner (0, 10).
//   gmsh two-layers.geo -2 -format msh41 -o two-layers.msh
Point(1) = {0, 0, 0};
Point(2) = {10, 0, 0};
Point(3) = {10, 5, 0};
Point(4) = {0, 5, 0};
Point(5) = {10, 10, 0};
Point(6) = {0, 10, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {3, 5};
Line(6) = {5, 6};
Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7};
Plane Surface(2) = {2};
Transfinite Curve{1, 3, 6} = 11;
Transfinite Curve{2, 4, 5, 7} = 6;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};
Physical Curve("bottom") = {1};
Physical Curve("top") = {6};
Physical Point("corner") = {6};
Physical Surface("soft") = {1};
Physical Surface("stiff") = {2};
