#!/usr/bin/python3
"""Writes the small test meshes of tests/unit/gmsh_mesh_test.cpp in the four variants of
gmsh's .msh format (2.2 and 4.1, ASCII and binary), the same mesh in each, as gmsh lays
them out (gmsh's documentation, "MSH file format"). Run from anywhere:
    /usr/bin/python3 tests/data/gmsh/write_meshes.py
Also imported by bench/gmsh_reading.py for its large grid."""
import os
import struct

DIM_OF_TYPE = {1: 1, 2: 2, 3: 2, 4: 3, 8: 1, 9: 2, 10: 2, 15: 0, 16: 2}


class Mesh:
    """nodes: {tag: (x, y, z)}; node_blocks: [(dim, entity, [tags], params or None)] (4.1);
    elements: [(tag, type, entity, [node tags])]; entities: {(dim, tag): [physical tags]};
    names: {(dim, tag): name}."""

    def __init__(self, nodes, elements, entities, names, node_blocks=None, comments=True):
        self.nodes = nodes
        self.elements = elements
        self.entities = entities
        self.names = names
        self.node_blocks = node_blocks or [(2, 1, sorted(nodes), None)]
        self.comments = comments


def physical_names(mesh):
    out = ["$PhysicalNames", str(len(mesh.names))]
    out += ['%d %d "%s"' % (d, t, n) for (d, t), n in sorted(mesh.names.items())]
    out.append("$EndPhysicalNames")
    return ("\n".join(out) + "\n").encode()


def header(version, binary):
    text = "$MeshFormat\n%s %d 8\n" % (version, 1 if binary else 0)
    b = text.encode()
    if binary:
        b += struct.pack("<i", 1) + b"\n"
    return b + b"$EndMeshFormat\n"


def extra_sections():
    # A section grip does not read, skipped by its end marker.
    return b"$Comments\nwritten by write_meshes.py; $Nodes in here is no section\n$EndComments\n"


def write_v22(mesh, binary):
    b = header("2.2", binary) + physical_names(mesh)
    if mesh.comments:
        b += extra_sections()
    tags = sorted(mesh.nodes)
    b += b"$Nodes\n%d\n" % len(tags)
    for t in tags:
        x, y, z = mesh.nodes[t]
        b += struct.pack("<iddd", t, x, y, z) if binary else ("%d %.17g %.17g %.17g\n" % (t, x, y, z)).encode()
    b += (b"\n" if binary else b"") + b"$EndNodes\n"
    # gmsh's 2.2 writer: an element once per physical group of its entity, each copy under a
    # new tag (the first copy keeps the element's tag here, so that all variants agree).
    records = []
    extra = 1000
    for tag, typ, entity, nodes in mesh.elements:
        groups = mesh.entities.get((DIM_OF_TYPE[typ], entity), [])
        for j, g in enumerate(groups):
            if j > 0:
                extra += 1
            records.append((tag if j == 0 else extra, typ, g, entity, nodes))
    b += b"$Elements\n%d\n" % len(records)
    if binary:
        i = 0
        while i < len(records):
            j = i
            while j < len(records) and records[j][1] == records[i][1]:
                j += 1
            b += struct.pack("<iii", records[i][1], j - i, 2)
            for tag, typ, g, entity, nodes in records[i:j]:
                b += struct.pack("<%di" % (3 + len(nodes)), tag, g, entity, *nodes)
            i = j
        b += b"\n"
    else:
        for tag, typ, g, entity, nodes in records:
            b += ("%d %d 2 %d %d %s\n" % (tag, typ, g, entity, " ".join(map(str, nodes)))).encode()
    b += b"$EndElements\n"
    return b


def write_v41(mesh, binary):
    b = header("4.1", binary) + physical_names(mesh)
    ents = [sorted(t for (d, t) in mesh.entities if d == dim) for dim in range(4)]
    # Entities: boxes are not read; zeros will do. Bounding entities: none.
    if binary:
        b += b"$Entities\n" + struct.pack("<4Q", *map(len, ents))
        for dim in range(4):
            for t in ents[dim]:
                ph = mesh.entities[(dim, t)]
                b += struct.pack("<i", t) + struct.pack("<%dd" % (3 if dim == 0 else 6), *([0.0] * (3 if dim == 0 else 6)))
                b += struct.pack("<Q", len(ph)) + struct.pack("<%di" % len(ph), *ph)
                if dim > 0:
                    b += struct.pack("<Q", 0)
        b += b"\n$EndEntities\n"
    else:
        b += b"$Entities\n" + (" ".join(map(str, map(len, ents))) + "\n").encode()
        for dim in range(4):
            for t in ents[dim]:
                ph = mesh.entities[(dim, t)]
                box = " ".join(["0"] * (3 if dim == 0 else 6))
                line = "%d %s %d %s" % (t, box, len(ph), " ".join(map(str, ph)))
                b += (line.rstrip() + (" 0" if dim > 0 else "") + "\n").encode()
        b += b"$EndEntities\n"
    if mesh.comments:
        b += extra_sections()
    blocks = mesh.node_blocks
    all_tags = [t for blk in blocks for t in blk[2]]
    head = (len(blocks), len(all_tags), min(all_tags), max(all_tags))
    if binary:
        b += b"$Nodes\n" + struct.pack("<4Q", *head)
        for dim, ent, tags, params in blocks:
            b += struct.pack("<iiiQ", dim, ent, 1 if params else 0, len(tags))
            b += struct.pack("<%dQ" % len(tags), *tags)
            for k, t in enumerate(tags):
                b += struct.pack("<3d", *mesh.nodes[t])
                if params:
                    b += struct.pack("<%dd" % len(params[k]), *params[k])
        b += b"\n$EndNodes\n"
    else:
        b += b"$Nodes\n%d %d %d %d\n" % head
        for dim, ent, tags, params in blocks:
            b += b"%d %d %d %d\n" % (dim, ent, 1 if params else 0, len(tags))
            b += "".join("%d\n" % t for t in tags).encode()
            for k, t in enumerate(tags):
                vals = list(mesh.nodes[t]) + (list(params[k]) if params else [])
                b += (" ".join("%.17g" % v for v in vals) + "\n").encode()
        b += b"$EndNodes\n"
    # Blocks: consecutive elements of one entity and type.
    eblocks = []
    for tag, typ, entity, nodes in mesh.elements:
        dim = DIM_OF_TYPE[typ]
        if eblocks and eblocks[-1][0] == (dim, entity, typ):
            eblocks[-1][1].append((tag, nodes))
        else:
            eblocks.append(((dim, entity, typ), [(tag, nodes)]))
    etags = [t for t, _, _, _ in mesh.elements]
    head = (len(eblocks), len(etags), min(etags), max(etags))
    if binary:
        b += b"$Elements\n" + struct.pack("<4Q", *head)
        for (dim, entity, typ), els in eblocks:
            b += struct.pack("<iiiQ", dim, entity, typ, len(els))
            for tag, nodes in els:
                b += struct.pack("<%dQ" % (1 + len(nodes)), tag, *nodes)
        b += b"\n$EndElements\n"
    else:
        b += b"$Elements\n%d %d %d %d\n" % head
        for (dim, entity, typ), els in eblocks:
            b += b"%d %d %d %d\n" % (dim, entity, typ, len(els))
            for tag, nodes in els:
                b += (" ".join(map(str, [tag] + nodes)) + "\n").encode()
        b += b"$EndElements\n"
    return b


VARIANTS = {"v22_ascii": lambda m: write_v22(m, False), "v22_binary": lambda m: write_v22(m, True),
            "v41_ascii": lambda m: write_v41(m, False), "v41_binary": lambda m: write_v41(m, True)}


def plate():
    """A 2 x 1 plate: one q4 on the left, two t3 on the right (the second written clockwise),
    a tool line above it (its nodes in no 2D element) and an unused node."""
    nodes = {10: (0, 0, 0), 20: (1, 0, 0), 30: (2, 0, 0), 40: (2, 1, 0), 50: (1, 1, 0), 60: (0, 1, 0),
             70: (0, 1.5, 0), 80: (2, 1.5, 0), 90: (5, 5, 0)}
    elements = [(8, 15, 1, [10]),                                  # point entity 1
                (4, 1, 1, [10, 20]), (5, 1, 1, [20, 30]),          # curve 1: the bottom
                (6, 1, 2, [30, 40]),                               # curve 2: the right side
                (7, 1, 5, [80, 70]),                               # curve 5: the tool
                (1, 3, 1, [10, 20, 50, 60]),                       # surface 1: q4
                (2, 2, 2, [20, 30, 40]), (3, 2, 2, [20, 50, 40])]  # surface 2: t3, t3 clockwise
    entities = {(0, 1): [21], (1, 1): [11], (1, 2): [13], (1, 5): [12], (2, 1): [1, 3], (2, 2): [7, 3]}
    names = {(0, 21): "corner", (1, 11): "bottom", (1, 12): "tool", (1, 13): "right", (2, 1): "left", (2, 3): "all"}
    return Mesh(nodes, elements, entities, names)


def quadratic():
    """A 3 x 1 strip of second-order elements on a 0.5 grid: a q9, a q8 and two t6 (the second
    clockwise); the bottom as 3-node lines (one written backwards), the q9's boundary as a
    closed loop of 3-node lines. Its nodes in two blocks in 4.1, the second parametric."""
    def tag(x, y):
        return 1 + int(round(2 * x)) + 7 * int(round(2 * y))
    nodes = {tag(i / 2, j / 2): (i / 2, j / 2, 0.0) for i in range(7) for j in range(3)}
    t = tag
    elements = [(1, 10, 1, [t(0, 0), t(1, 0), t(1, 1), t(0, 1), t(.5, 0), t(1, .5), t(.5, 1), t(0, .5), t(.5, .5)]),
                (2, 16, 2, [t(1, 0), t(2, 0), t(2, 1), t(1, 1), t(1.5, 0), t(2, .5), t(1.5, 1), t(1, .5)]),
                (3, 9, 3, [t(2, 0), t(3, 0), t(3, 1), t(2.5, 0), t(3, .5), t(2.5, .5)]),
                (4, 9, 3, [t(2, 0), t(2, 1), t(3, 1), t(2, .5), t(2.5, 1), t(2.5, .5)]),
                (5, 8, 1, [t(0, 0), t(1, 0), t(.5, 0)]), (6, 8, 1, [t(2, 0), t(1, 0), t(1.5, 0)]),
                (7, 8, 1, [t(2, 0), t(3, 0), t(2.5, 0)]),
                (8, 8, 2, [t(1, 0), t(1, 1), t(1, .5)]), (9, 8, 2, [t(1, 1), t(0, 1), t(.5, 1)]),
                (10, 8, 2, [t(0, 1), t(0, 0), t(0, .5)]), (11, 8, 2, [t(0, 0), t(1, 0), t(.5, 0)])]
    entities = {(1, 1): [1], (1, 2): [2], (2, 1): [5], (2, 2): [5], (2, 3): [6]}
    names = {(1, 1): "bottom", (1, 2): "square_edge", (2, 5): "quads", (2, 6): "triangles"}
    on_curve = [t(x / 2, 0) for x in range(7)]
    rest = [n for n in sorted(nodes) if n not in on_curve]
    blocks = [(1, 1, on_curve, [(x / 2,) for x in range(7)]), (2, 1, rest, None)]
    return Mesh(nodes, elements, entities, names, blocks)


def plate_with_tetrahedron():
    """The plate and a 4-node tetrahedron (tag 9) in a volume: refused in binary too."""
    mesh = plate()
    mesh.nodes[100] = (0.5, 0.5, 1.0)
    mesh.elements.append((9, 4, 1, [10, 20, 50, 100]))
    mesh.entities[(3, 1)] = [4]
    return mesh


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    meshes = (("plate", plate()), ("quadratic", quadratic()), ("tetrahedron", plate_with_tetrahedron()))
    for name, mesh in meshes:
        for variant, write in VARIANTS.items():
            if name == "tetrahedron" and "binary" not in variant:
                continue
            with open(os.path.join(here, "%s_%s.msh" % (name, variant)), "wb") as f:
                f.write(write(mesh))


if __name__ == "__main__":
    main()
