// Rigid tools for tests/verification/gmsh_scene_test.cpp: curves only (no 2D elements).
// "flat": the sliding block's flat, from (40, 0) to (-40, 0) (solid below, on its left).
// "arc": a half circle of radius 2 about (0, 15), from (2, 15) counter-clockwise to (-2, 15),
// meshed with 3-node lines (gmsh -1 -order 2): arcs through their mid nodes.
Point(1) = {40, 0, 0};
Point(2) = {-40, 0, 0};
Line(1) = {1, 2};
Transfinite Curve{1} = 2;
Point(3) = {0, 15, 0};
Point(4) = {2, 15, 0};
Point(5) = {0, 17, 0};
Point(6) = {-2, 15, 0};
Circle(2) = {4, 3, 5};
Circle(3) = {5, 3, 6};
Transfinite Curve{2, 3} = 5;
Physical Curve("flat") = {1};
Physical Curve("arc") = {2, 3};
