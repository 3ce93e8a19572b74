// Hertz line contact on 6-node triangles (schemas/examples/hertz-t6.json): the half-disc of
// schemas/examples/hertz.json (R = 10 mm, centre (0, 0), the arc below its diameter), meshed by
// gmsh with elements of 0.05 mm within 0.8 mm of the pole, growing to 1.5 mm. Second order
// (t6): the mid-side nodes lie on the arc. Mesh it with
//   gmsh hertz-t6.geo -2 -order 2 -format msh41 -o hertz-t6.msh
// Physical curves: "contact" (the arc within 1 mm of the pole), "arc" (the whole arc),
// "diameter"; physical surface "disc".
R = 10;
theta = 1.0 / R;  // the contact curve's ends: 1 mm of arc either side of the pole
Point(1) = {0, 0, 0};
Point(2) = {R, 0, 0};
Point(3) = {R * Sin(theta), -R * Cos(theta), 0};
Point(4) = {0, -R, 0};
Point(5) = {-R * Sin(theta), -R * Cos(theta), 0};
Point(6) = {-R, 0, 0};
Circle(1) = {6, 1, 5};
Circle(2) = {5, 1, 4};
Circle(3) = {4, 1, 3};
Circle(4) = {3, 1, 2};
Line(5) = {2, 6};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Field[1] = Distance;
Field[1].PointsList = {4};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.05;
Field[2].SizeMax = 1.5;
Field[2].DistMin = 0.8;
Field[2].DistMax = 6;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Physical Curve("contact") = {2, 3};
Physical Curve("arc") = {1, 2, 3, 4};
Physical Curve("diameter") = {5};
Physical Surface("disc") = {1};
