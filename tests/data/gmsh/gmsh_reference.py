#!/usr/bin/python3
"""gmsh's own view of three small meshes, for tests/unit/gmsh_python_test.cpp.
    /usr/bin/python3 gmsh_reference.py OUTDIR
meshes a plate (a quad-meshed square beside a triangle-meshed one, a tool line above them,
physical surfaces, curves and a point) with Debian's gmsh Python module at order 1, at order
2 (t6, q9) and at order 2 incomplete (t6, q8); writes each as OUTDIR/<case>_<variant>.msh in
the four variants (2.2 and 4.1, ASCII and binary; 4.1 also with parametric coordinates) and what gmsh's API reports as
OUTDIR/<case>.json. Exit code 77 when the module is not importable."""
import json
import os
import sys

try:
    import gmsh
except ImportError:
    sys.exit(77)

CASES = {"linear": (1, 0), "quadratic": (2, 0), "serendipity": (2, 1)}
# The last two with the nodes' parametric coordinates (Mesh.SaveParametric), which grip skips.
VARIANTS = {"v22_ascii": (2.2, 0, 0), "v22_binary": (2.2, 1, 0), "v41_ascii": (4.1, 0, 0), "v41_binary": (4.1, 1, 0),
            "v41_parametric_ascii": (4.1, 0, 1), "v41_parametric_binary": (4.1, 1, 1)}


def plate():
    geo = gmsh.model.geo
    h = 0.3
    p = [geo.addPoint(x, y, 0, h) for x, y in ((0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1))]
    bottom = [geo.addLine(p[0], p[1]), geo.addLine(p[1], p[2])]
    right, top2, middle, top1, left = (geo.addLine(p[2], p[3]), geo.addLine(p[3], p[4]),
                                       geo.addLine(p[1], p[4]), geo.addLine(p[4], p[5]), geo.addLine(p[5], p[0]))
    quads = geo.addPlaneSurface([geo.addCurveLoop([bottom[0], middle, top1, left])])
    triangles = geo.addPlaneSurface([geo.addCurveLoop([bottom[1], right, top2, -middle])])
    tool = geo.addLine(geo.addPoint(2, 1.5, 0, h), geo.addPoint(0, 1.5, 0, h))
    geo.mesh.setRecombine(2, quads)
    geo.synchronize()
    model = gmsh.model
    model.setPhysicalName(2, model.addPhysicalGroup(2, [quads], 1), "quads")
    model.addPhysicalGroup(2, [triangles], 7)  # unnamed: surface_7
    model.setPhysicalName(2, model.addPhysicalGroup(2, [quads, triangles], 3), "all")
    model.setPhysicalName(1, model.addPhysicalGroup(1, bottom, 11), "bottom")
    model.setPhysicalName(1, model.addPhysicalGroup(1, [tool], 12), "tool")
    model.setPhysicalName(0, model.addPhysicalGroup(0, [p[0]], 21), "corner")


def report():
    tags, coords, _ = gmsh.model.mesh.getNodes()
    nodes = {int(t): [coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]] for i, t in enumerate(tags)}
    elements = []
    types, etags, enodes = gmsh.model.mesh.getElements(2)
    for typ, ts, ns in zip(types, etags, enodes):
        k = len(ns) // len(ts)
        elements += [[int(typ), int(t), [int(n) for n in ns[i * k:(i + 1) * k]]] for i, t in enumerate(ts)]
    groups = []
    for dim, tag in gmsh.model.getPhysicalGroups():
        members = []
        for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
            types, etags, enodes = gmsh.model.mesh.getElements(dim, entity)
            for typ, ts, ns in zip(types, etags, enodes):
                k = len(ns) // len(ts)
                members += [[int(t), [int(n) for n in ns[i * k:(i + 1) * k]]] for i, t in enumerate(ts)]
        group_nodes, _ = gmsh.model.mesh.getNodesForPhysicalGroup(dim, tag)
        groups.append({"dimension": dim, "tag": tag, "name": gmsh.model.getPhysicalName(dim, tag),
                       "elements": members, "nodes": sorted(int(n) for n in group_nodes)})
    return {"nodes": nodes, "elements": elements, "groups": groups}


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    gmsh.initialize(["gmsh", "-v", "0"])
    for case, (order, incomplete) in CASES.items():
        gmsh.clear()
        gmsh.model.add(case)
        plate()
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", incomplete)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(order)
        for variant, (version, binary, parametric) in VARIANTS.items():
            gmsh.option.setNumber("Mesh.MshFileVersion", version)
            gmsh.option.setNumber("Mesh.Binary", binary)
            gmsh.option.setNumber("Mesh.SaveParametric", parametric)
            gmsh.write(os.path.join(out, "%s_%s.msh" % (case, variant)))
        with open(os.path.join(out, case + ".json"), "w") as f:
            json.dump(report(), f)
    gmsh.finalize()


if __name__ == "__main__":
    main()
