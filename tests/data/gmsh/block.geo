// The sliding block of schemas/examples/sliding-block.json (20 x 10 mm), meshed by gmsh:
// 20 x 10 structured quadrilaterals. Physical curves: bottom, top (the body's contact and loaded sides).
Point(1) = {-10, 0, 0};
Point(2) = {10, 0, 0};
Point(3) = {10, 10, 0};
Point(4) = {-10, 10, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 21;
Transfinite Curve{2, 4} = 11;
Transfinite Surface{1};
Recombine Surface{1};
Physical Curve("bottom") = {1};
Physical Curve("top") = {3};
Physical Surface("block") = {1};
