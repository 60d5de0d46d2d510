#!/usr/bin/env python3
"""Converts real assemblies modelled by others (public repositories) into the AutomationML
products the cell reads: one .aml per assembly, the part meshes as the source has them (or,
where the source scales a mesh unevenly, an OBJ in metres), the source's licence and a
SOURCE.md that says where every number came from.

    convert_assemblies.py --repo NAME=GIT_DIR [--repo ...] --out DIR [ASSEMBLY ...]

GIT_DIR is a clone (or bare mirror) of the repository NAME of the table below; the files are
read from its HEAD with `git show`. Without ASSEMBLY names, every assembly whose repository is
given is converted. Python 3 and git only.

How an assembly becomes a product (docs/products.md, "Real assemblies"):
- Each part's assembled pose comes from the source (its simulation's poses, or the relative
  poses its authors wrote down); the product is turned so that its up is +y.
- The links are the source's connections where it names them, else the pairs of parts whose
  boxes touch. A link joins an interface at the partner's origin on one part with the other
  part's origin, so the cell's placement puts every part where the source has it.
- Nothing is corrected: threads that overlap, gaps, open meshes stay as the authors left them.
"""
import argparse
import ast
import math
import os
import struct
import subprocess
import sys
import xml.etree.ElementTree as ET

# --- small linear algebra -----------------------------------------------------------------

I3 = [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))] for i in range(len(a))]


def apply(r, v):
    return [sum(r[i][k] * v[k] for k in range(3)) for i in range(3)]


def transpose(r):
    return [[r[j][i] for j in range(3)] for i in range(3)]


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return [[1, 0, 0], [0, c, -s], [0, s, c]]


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, 0, s], [0, 1, 0], [-s, 0, c]]


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def euler_xyz(rx, ry, rz):
    """Rotations about the fixed x, then y, then z axes: R = Rz Ry Rx (AutomationML's Frame,
    scipy's from_euler("xyz"), FurnitureBench's rot_mat)."""
    return matmul(rot_z(rz), matmul(rot_y(ry), rot_x(rx)))


def to_euler_xyz(r):
    """(rx, ry, rz) in radians with R = Rz Ry Rx."""
    sy = -r[2][0]
    sy = max(-1.0, min(1.0, sy))
    ry = math.asin(sy)
    if abs(sy) < 1 - 1e-9:
        return math.atan2(r[2][1], r[2][2]), ry, math.atan2(r[1][0], r[0][0])
    return math.atan2(-r[1][2], r[1][1]), ry, 0.0  # gimbal lock: rz folded into rx


def quat_wxyz(w, x, y, z):
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


# The turn that makes a source's up +y.
UP = {"+y": I3, "-y": rot_x(math.pi), "+z": [[1, 0, 0], [0, 0, 1], [0, -1, 0]], "-z": [[1, 0, 0], [0, 0, -1], [0, 1, 0]]}

# --- reading the source -------------------------------------------------------------------


class Repo:
    def __init__(self, name, git_dir):
        self.name, self.git_dir = name, git_dir
        self.commit = self.git("rev-parse", "HEAD").decode().strip()

    def git(self, *args):
        return subprocess.run(["git", "--git-dir", self.git_dir, *args], capture_output=True, check=True).stdout

    def read(self, path):
        data = self.git("show", "HEAD:" + path)
        if not data:
            raise SystemExit(f"{self.name}: {path} is empty in the snapshot (a large file it lacks?)")
        return data


def mesh_vertices(data, name):
    """The vertices of an OBJ or STL (binary or ASCII) file, in its own units."""
    if name.lower().endswith(".obj"):
        out = []
        for line in data.decode(errors="replace").splitlines():
            if line.startswith("v "):
                x, y, z = line.split()[1:4]
                out.append((float(x), float(y), float(z)))
        return out
    if data[:5] == b"solid" and b"facet" in data[:400]:
        return [tuple(float(x) for x in line.split()[1:4]) for line in data.decode().splitlines()
                if line.strip().startswith("vertex")]
    count = struct.unpack_from("<I", data, 80)[0]
    out = []
    for i in range(count):
        values = struct.unpack_from("<12f", data, 84 + 50 * i)
        out += [values[3:6], values[6:9], values[9:12]]
    return out


def scaled_obj(data, name, scale):
    """The mesh as OBJ text in metres, each axis scaled by its factor (faces as they were)."""
    lines = ["# %s scaled to metres by (%.9g, %.9g, %.9g) as the source's simulation scales it" % (name, *scale)]
    if name.lower().endswith(".obj"):
        for line in data.decode(errors="replace").splitlines():
            if line.startswith("v "):
                x, y, z = (float(t) for t in line.split()[1:4])
                lines.append("v %.9g %.9g %.9g" % (x * scale[0], y * scale[1], z * scale[2]))
            elif line.startswith(("f ", "o ", "g ")):
                lines.append(line)
        return "\n".join(lines) + "\n"
    vertices = mesh_vertices(data, name)
    for x, y, z in vertices:
        lines.append("v %.9g %.9g %.9g" % (x * scale[0], y * scale[1], z * scale[2]))
    for i in range(0, len(vertices), 3):
        lines.append("f %d %d %d" % (i + 1, i + 2, i + 3))
    return "\n".join(lines) + "\n"


class Part:
    def __init__(self, name, path, rotation, translation, scale):
        self.name = name
        self.path = path                # in the repository
        self.rotation = rotation        # assembled, source's frame
        self.translation = translation  # m, source's frame
        self.scale = scale              # file units -> m: a number, or one per axis


# --- the sources --------------------------------------------------------------------------


def asap(repo, spec):
    """yunshengtian/ASAP: assets/<name>/original/config.json, "final_state" per part:
    [x, y, z, rx, ry, rz] in the mesh's units and radians (scipy from_euler("xyz"))."""
    import json
    folder = spec["folder"]
    config = json.loads(repo.read(folder + "/config.json"))
    parts = []
    for key, state in sorted(config.items(), key=lambda kv: int(kv[0])):
        x, y, z, rx, ry, rz = state["final_state"]
        s = spec["scale"]
        parts.append(Part(spec["names"].get(key, "part" + key), f"{folder}/{key}.obj", euler_xyz(rx, ry, rz),
                          [x * s, y * s, z * s], s))
    return parts, None


class PoseExpression(ast.NodeVisitor):
    """Evaluates FurnitureBench's pose expressions: numbers, np.pi, + - * /, lists,
    get_mat(position, angles) and @ between them (4x4 matrices as [R, t])."""

    def visit_Constant(self, node):
        return float(node.value)

    def visit_UnaryOp(self, node):
        v = self.visit(node.operand)
        return -v if isinstance(node.op, ast.USub) else v

    def visit_BinOp(self, node):
        a, b = self.visit(node.left), self.visit(node.right)
        if isinstance(node.op, ast.MatMult):
            return (matmul(a[0], b[0]), [x + y for x, y in zip(apply(a[0], b[1]), a[1])])
        operations = {ast.Add: lambda: a + b, ast.Sub: lambda: a - b, ast.Mult: lambda: a * b, ast.Div: lambda: a / b}
        return operations[type(node.op)]()

    def visit_Attribute(self, node):
        if node.attr == "pi":
            return math.pi
        raise ValueError("unknown name " + ast.dump(node))

    def visit_List(self, node):
        return [self.visit(e) for e in node.elts]

    def visit_Call(self, node):
        if getattr(node.func, "id", "") != "get_mat":
            raise ValueError("unknown call " + ast.dump(node.func))
        position, angles = (self.visit(a) for a in node.args)
        return (euler_xyz(*angles), position)

    def generic_visit(self, node):
        raise ValueError("cannot evaluate " + ast.dump(node))


def furniture_bench(repo, spec):
    """clvrai/furniture-bench: furniture_bench/furniture/<name>.py lists the parts and, for
    pairs (i, j), the pose of part j in part i's frame where they are assembled; where a pair
    lists several places (four legs), the k-th part of that kind takes the k-th."""
    name = spec["furniture"]
    tree = ast.parse(repo.read(f"furniture_bench/furniture/{name}.py").decode())
    keys, poses, aliases = [], {}, {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Attribute) and node.targets[0].attr == "parts":
            for call in node.value.elts:
                keys.append(call.args[0].slice.value)
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Subscript) and \
                getattr(node.targets[0].value, "attr", "") == "assembled_rel_poses":
            pair = tuple(int(e.value) for e in node.targets[0].slice.elts)
            if isinstance(node.value, ast.Subscript):
                aliases[pair] = tuple(int(e.value) for e in node.value.slice.elts)
            else:
                poses[pair] = [PoseExpression().visit(e) for e in node.value.elts]
    places = {}  # pair -> (the list it uses, which place of it)
    used = {}
    for pair in sorted(list(poses) + list(aliases), key=lambda p: p[1]):
        source = aliases.get(pair, pair)
        k = used.get(source, 0)
        used[source] = k + 1
        places[pair] = (source, k)
    world = {0: (I3, [0.0, 0.0, 0.0])}
    links = []
    while len(world) < len(keys):
        grown = False
        for (i, j), (source, k) in places.items():
            if i in world and j not in world:
                r, t = poses[source][k]
                ri, ti = world[i]
                world[j] = (matmul(ri, r), [a + b for a, b in zip(apply(ri, t), ti)])
                links.append((i, j))
                grown = True
        if not grown:
            raise SystemExit(f"{name}: parts {sorted(set(range(len(keys))) - set(world))} have no pose")
    mesh_dir = f"furniture_bench/assets/furniture/mesh/{name}"
    files = set(repo.git("ls-tree", "--name-only", "HEAD", mesh_dir + "/").decode().split())
    parts = []
    for index, key in enumerate(keys):
        path = next((p for p in (f"{mesh_dir}/{key}.obj", f"{mesh_dir}/{name}_{key}.obj") if p in files), None)
        if not path:
            raise SystemExit(f"{name}: no mesh for part {key} in {mesh_dir}")
        parts.append(Part(key, path, world[index][0], world[index][1], 1.0))
    return parts, links


def ikea(repo, spec):
    """clvrai/furniture (the IKEA furniture assembly environment): the MuJoCo model's
    <worldbody> bodies stand assembled (pos, quat w x y z), each with one mesh geom whose
    asset scales the STL to metres; <equality><weld> names the joined pairs."""
    name = spec["furniture"]
    folder = "furniture/env/models/assets/objects"
    root = ET.fromstring(repo.read(f"{folder}/{name}.xml"))
    meshes = {m.get("name"): m for m in root.iter("mesh")}
    parts, index = [], {}
    for body in root.find("worldbody").findall("body"):
        geom = next((g for g in body.findall("geom") if g.get("type") == "mesh" or g.get("mesh")), None)
        if geom is None:
            continue
        mesh = meshes[geom.get("mesh")]
        scale = [float(s) for s in mesh.get("scale", "1 1 1").split()]
        r = quat_wxyz(*[float(v) for v in body.get("quat", "1 0 0 0").split()])
        t = [float(v) for v in body.get("pos", "0 0 0").split()]
        if geom.get("quat") or geom.get("pos"):
            rg = quat_wxyz(*[float(v) for v in geom.get("quat", "1 0 0 0").split()])
            tg = [float(v) for v in geom.get("pos", "0 0 0").split()]
            t = [a + b for a, b in zip(apply(r, tg), t)]
            r = matmul(r, rg)
        index[body.get("name")] = len(parts)
        parts.append(Part(body.get("name").split("_", 1)[-1], f"{folder}/{mesh.get('file')}", r, t,
                          scale[0] if len(set(scale)) == 1 else scale))
    links = []
    for weld in root.iter("weld"):
        a, b = index.get(weld.get("body1")), index.get(weld.get("body2"))
        if a is not None and b is not None and (a, b) not in links and (b, a) not in links:
            links.append((a, b))
    return parts, links


def number(text):
    """A number as the sources write them: 0.5, -pi/2, 2*pi/3."""
    return PoseExpression().visit(ast.parse(str(text).replace("pi", "np.pi"), mode="eval").body)


def compose(a, b):
    return matmul(a[0], b[0]), [x + y for x, y in zip(apply(a[0], b[1]), a[1])]


def inverse(a):
    r = transpose(a[0])
    return r, [-x for x in apply(r, a[1])]


def o2ac(repo, spec):
    """o2ac/o2ac-ur's assembly database (WRS task boards): frames_to_mate.csv mates a subframe
    of a parent part to one of a child part, with an offset (rpy, xyz) in the parent's; each
    part's subframes (object_metadata/<name>.yaml, pose_xyzrpy) and mesh pose. Composed as its
    assembly_reader.py does: child = parent * parent_subframe * offset * child_subframe^-1,
    the first parent at the origin. Meshes in millimetres. Needs PyYAML."""
    import csv
    import io
    import yaml
    folder = spec["folder"]
    listed = yaml.safe_load(repo.read(folder + "/parts_list.yaml"))["parts_list"]
    by_id = {p["id"]: p for p in listed}
    meta = {}
    for p in listed:
        try:
            meta[p["id"]] = yaml.safe_load(repo.read(f"{folder}/object_metadata/{p['name'].strip()}.yaml")) or {}
        except subprocess.CalledProcessError:
            meta[p["id"]] = {}

    def xyzrpy(values):
        v = [number(x) for x in values]
        return euler_xyz(v[3], v[4], v[5]), v[:3]

    def subframe(pid, name):
        for sub in meta[pid].get("subframes", []):
            if sub["name"] == name:
                return xyzrpy(sub["pose_xyzrpy"])
        raise SystemExit(f"o2ac: part {pid} has no subframe {name}")

    world, links = {}, []
    for row in csv.reader(io.StringIO(repo.read(folder + "/frames_to_mate.csv").decode())):
        if not row or row[0].strip().startswith("#") or row[0].strip() == "parent_frame":
            continue
        row = [x.strip() for x in row]
        parent, child = (f.split("_") for f in row[:2])
        pid, cid = int(parent[1]), int(child[1])
        world.setdefault(pid, (I3, [0.0, 0.0, 0.0]))
        offset = (euler_xyz(number(row[2]), number(row[3]), number(row[4])), [number(x) for x in row[5:8]])
        world[cid] = compose(compose(compose(world[pid], subframe(pid, "_".join(parent[2:]))), offset),
                             inverse(subframe(cid, "_".join(child[2:]))))
        links.append((pid, cid))
    ids = sorted(world)
    parts = []
    for pid in ids:
        pose = world[pid]
        if meta[pid].get("mesh_pose"):
            pose = compose(pose, xyzrpy(meta[pid]["mesh_pose"][0]["pose_xyzrpy"]))
        parts.append(Part(by_id[pid]["name"].strip(), f"{folder}/meshes/{by_id[pid]['cad']}", pose[0], pose[1], 0.001))
    index = {pid: k for k, pid in enumerate(ids)}
    return parts, [(index[a], index[b]) for a, b in links]


def identity(repo, spec):
    """Parts modelled in one frame (IsaacGymEnvs' Factory and IndustReal assets: the plug's
    pose equals the socket's when inserted)."""
    return [Part(n, p, I3, [0.0, 0.0, 0.0], spec.get("scale", 1.0)) for n, p in spec["parts"]], spec.get("links")


READERS = {"asap": asap, "furniture-bench": furniture_bench, "ikea": ikea, "identity": identity, "o2ac": o2ac}

# --- the assemblies -----------------------------------------------------------------------

ISAAC = "assets/industreal/mesh"
ASSEMBLIES = {
    "asap-beam-frame": dict(repo="yunshengtian/ASAP", reader="asap", up="+z", licence="LICENSE",
                            folder="assets/beam_assembly/original", scale=0.01,  # inch lumber in cm
                            names={"0": "beam_left", "1": "beam_right", "2": "post_left", "3": "post_right", "6": "base"},
                            note="A post-and-beam frame: a base beam, two posts with tenons, two beams on them."),
    **{f"fb-{n}": dict(repo="clvrai/furniture-bench", reader="furniture-bench", up="-y", licence="LICENSE", furniture=n,
                       note=f"FurnitureBench's {n.replace('_', ' ')} (3D-printed furniture, parts modelled with their threads).")
       for n in ["cabinet", "chair", "desk", "drawer", "lamp", "round_table", "square_table", "stool"]},
    **{f"ikea-{n}": dict(repo="clvrai/furniture", reader="ikea", up="+z", licence="LICENSE", furniture=n,
                         note=f"The IKEA furniture assembly environment's {n} (simplified furniture meshes).")
       for n in ["bookcase_billy_0190", "box_ivar_0666", "cabinet_lillagen_0933", "chair_agne_0010",
                 "desk_fredrik_0430", "shelf_lillagen_0927", "table_dockstra_0279", "table_lack_0825",
                 "table_liden_0921"]},
    "industreal-round-peg": dict(repo="isaac-sim/IsaacGymEnvs", reader="identity", up="+z", licence="LICENSE.txt",
                                 parts=[("socket", f"{ISAAC}/industreal_pegs/industreal_tray_insert_round_peg_8mm.obj"),
                                        ("peg", f"{ISAAC}/industreal_pegs/industreal_round_peg_8mm.obj")],
                                 note="IndustReal's 8 mm round peg in its socket (a clearance fit)."),
    "industreal-rectangular-peg": dict(repo="isaac-sim/IsaacGymEnvs", reader="identity", up="+z", licence="LICENSE.txt",
                                       parts=[("socket", f"{ISAAC}/industreal_pegs/industreal_tray_insert_rectangular_peg_8mm.obj"),
                                              ("peg", f"{ISAAC}/industreal_pegs/industreal_rectangular_peg_8mm.obj")],
                                       note="IndustReal's 8 mm rectangular peg in its socket."),
    # Not kept in tests/data/real: its meshes are vendors' CAD whose terms are not checked.
    "o2ac-wrs2020": dict(repo="o2ac/o2ac-ur", reader="o2ac", up="+y", licence="LICENSE",
                         folder="catkin_ws/src/o2ac_assembly_database/config/wrs_assembly_2020",
                         note="The WRS 2020 assembly task board: base, two plates, motor, pulleys, bearing, shaft, "
                              "idler with its pin, nut and washer (the belt and screws left out)."),
    "factory-nut-bolt-m12": dict(repo="isaac-sim/IsaacGymEnvs", reader="identity", up="+z", licence="LICENSE.txt",
                                 parts=[("bolt", "assets/factory/mesh/factory_nut_bolt/factory_bolt_m12_loose.obj"),
                                        ("nut", "assets/factory/mesh/factory_nut_bolt/factory_nut_m12_loose_subdiv_3x.obj")],
                                 note="Factory's M12 nut on its bolt, threads modelled."),
}

# --- writing the product ------------------------------------------------------------------


def box_of(vertices, part):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    s = part.scale if isinstance(part.scale, list) else [part.scale] * 3
    for v in vertices:
        w = apply(part.rotation, [v[0] * s[0], v[1] * s[1], v[2] * s[2]])
        for k in range(3):
            lo[k] = min(lo[k], w[k] + part.translation[k])
            hi[k] = max(hi[k], w[k] + part.translation[k])
    return lo, hi


def touching(a, b, gap=5e-4):
    return all(a[0][k] <= b[1][k] + gap and b[0][k] <= a[1][k] + gap for k in range(3))


UNITS = {1.0: "m", 0.01: "cm", 0.001: "mm", 0.0254: "in"}


def fmt(v):
    return ",".join("%.9g" % (0.0 if abs(x) < 1e-15 else x) for x in v)


def write(name, spec, repo, out_dir):
    parts, links = READERS[spec["reader"]](repo, spec)
    up = UP[spec["up"]]
    for p in parts:  # turned so that up is +y
        p.rotation, p.translation = matmul(up, p.rotation), apply(up, p.translation)
    folder = os.path.join(out_dir, name)
    os.makedirs(os.path.join(folder, "meshes"), exist_ok=True)
    files = {}
    boxes = []
    for p in parts:
        data = repo.read(p.path)
        boxes.append(box_of(mesh_vertices(data, p.path), p))
        base = os.path.basename(p.path)
        if isinstance(p.scale, list) or p.scale not in UNITS:
            # Scaled unevenly, or by no unit a LengthUnit names: written out in metres.
            scale = p.scale if isinstance(p.scale, list) else [p.scale] * 3
            written = scaled_obj(data, base, scale)
            base = os.path.splitext(base)[0] + ".obj"
            open(os.path.join(folder, "meshes", base), "w").write(written)
            files[base] = "m"
        else:
            open(os.path.join(folder, "meshes", base), "wb").write(data)
            files[base] = UNITS[p.scale]
        p.file = base
    if links is None:
        links = [(i, j) for i in range(len(parts)) for j in range(i + 1, len(parts)) if touching(boxes[i], boxes[j])]
    open(os.path.join(folder, "LICENSE.txt"), "wb").write(repo.read(spec["licence"]))
    lines = ['<?xml version="1.0" encoding="utf-8"?>',
             f"<!-- {spec['note']} Converted by tests/data/real/convert_assemblies.py from",
             f"     {spec['repo']} at {repo.commit}; see SOURCE.md. -->",
             f'<CAEXFile SchemaVersion="3.0" FileName="{name}.aml" xmlns="http://www.dke.de/CAEX">',
             '  <InstanceHierarchy Name="Order">',
             f'    <InternalElement Name="{name}" ID="{name}">']
    for p in parts:
        rx, ry, rz = (math.degrees(a) for a in to_euler_xyz(p.rotation))
        lines.append(f'      <InternalElement Name="{p.name}" ID="{p.name}" RefBaseSystemUnitPath="Parts/{p.name}">')
        lines.append(f'        <Attribute Name="orientation" Unit="deg"><Value>{fmt([rx, ry, rz])}</Value></Attribute>')
        lines.append("      </InternalElement>")
    for i, j in links:
        a, b = parts[i], parts[j]
        lines.append(f'      <InternalLink Name="{a.name}-{b.name}" RefPartnerSideA="{a.name}:to_{b.name}" '
                     f'RefPartnerSideB="{b.name}:to_{a.name}" />')
    lines += ["    </InternalElement>", "  </InstanceHierarchy>", '  <SystemUnitClassLib Name="Parts">']
    for index, p in enumerate(parts):
        lines.append(f'    <SystemUnitClass Name="{p.name}">')
        for i, j in links:
            if index not in (i, j):
                continue
            other = parts[j if index == i else i]
            # The link's point: the origin of the link's second part, in this part's frame.
            where = [0.0, 0.0, 0.0]
            if index == i:
                where = apply(transpose(p.rotation), [b - a for a, b in zip(p.translation, parts[j].translation)])
            lines.append(f'      <Attribute Name="to_{other.name}" Unit="m"><DefaultValue>{fmt(where)}</DefaultValue></Attribute>')
            lines.append(f'      <ExternalInterface Name="to_{other.name}" ID="{p.name}-to_{other.name}" />')
        lines.append(f'      <ExternalInterface Name="geometry" ID="{p.name}-geometry" RefBaseClassPath='
                     '"AutomationMLInterfaceClassLib/AutomationMLBaseInterface/ExternalDataConnector/ExternalDataReference">')
        lines.append(f'        <Attribute Name="refURI"><Value>meshes/{p.file}</Value></Attribute>')
        lines.append(f'        <Attribute Name="LengthUnit"><Value>{files[p.file]}</Value></Attribute>')
        lines.append("      </ExternalInterface>")
        lines.append("    </SystemUnitClass>")
    lines += ["  </SystemUnitClassLib>", "</CAEXFile>", ""]
    open(os.path.join(folder, name + ".aml"), "w").write("\n".join(lines))
    source = [f"# {name}", "", spec["note"], "",
              f"- Source: https://github.com/{spec['repo']} at commit {repo.commit}",
              f"- Licence: the repository's `{spec['licence']}`, copied here as LICENSE.txt",
              f"- Read by: `{spec['reader']}` in convert_assemblies.py ({READERS[spec['reader']].__doc__.split(chr(10))[0]})",
              f"- Up: the source's {spec['up']} is the product's +y", "", "| part | mesh (source path) | unit |", "|---|---|---|"]
    source += [f"| {p.name} | `{p.path}` | {files[p.file]} |" for p in parts]
    source += ["", "Links: " + ", ".join(f"{parts[i].name}-{parts[j].name}" for i, j in links), ""]
    open(os.path.join(folder, "SOURCE.md"), "w").write("\n".join(source))
    print(f"{name}: {len(parts)} parts, {len(links)} links -> {folder}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repo", action="append", default=[], metavar="NAME=GIT_DIR")
    parser.add_argument("--out", required=True)
    parser.add_argument("assemblies", nargs="*")
    args = parser.parse_args()
    repos = {}
    for given in args.repo:
        repo_name, _, git_dir = given.partition("=")
        repos[repo_name] = Repo(repo_name, git_dir)
    names = args.assemblies or [n for n, s in ASSEMBLIES.items() if s["repo"] in repos]
    for name in names:
        spec = ASSEMBLIES.get(name)
        if not spec:
            raise SystemExit(f"unknown assembly {name}; known: {', '.join(ASSEMBLIES)}")
        if spec["repo"] not in repos:
            raise SystemExit(f"{name} needs --repo {spec['repo']}=GIT_DIR")
        write(name, spec, repos[spec["repo"]], args.out)


if __name__ == "__main__":
    sys.exit(main())
