"""2D meshes from Gmsh files: .msh (ASCII formats 4.1 and 2.2) read here, other .msh versions
and binary files converted to ASCII 4.1 by the `gmsh` command-line tool, .geo meshed by it.
Only files of the server's operator are read this way (SetupBody.mesh_path under the data
directory, see paths.py); a mesh received on the wire is MeshData (mesh_data.py), which never
reaches gmsh.

The mesh read is what the C++ reader (subdomain/numerics/gmsh_reader.hpp) reads:
  - area elements of every entity in a 2D physical group (of every 2D entity when the file has
    no 2D physical group): 3-node triangles, 6-node triangles, 4-node quadrilaterals, in blocks
    ordered triangle3, triangle6, quadrilateral4;
  - every 1D physical group is a named boundary (its name, or its tag when unnamed) made of
    2-node or 3-node lines;
  - nodes: those used by the elements and boundary edges, numbered 0.. in ascending Gmsh tag
    order (the node ids of the protocol);
  - clockwise elements are reordered counter-clockwise; coordinates must lie in z = 0.
Every problem of the mesh raises InputError naming the source. A temporary directory (TMPDIR,
else /tmp) that cannot hold the files given to gmsh raises RequestError INTERNAL naming the
source and the directory: the server's environment is at fault, not the mesh.
"""

import contextlib
import os
import pathlib
import shutil
import subprocess
import tempfile

import numpy as np

from .errors import InputError, RequestError

TRIANGLE3, TRIANGLE6, QUADRILATERAL4 = "triangle3", "triangle6", "quadrilateral4"
LINE2, LINE3 = "line2", "line3"
# Solid cells (protocol 2.4, received as MeshData only): Gmsh's node order.
TETRAHEDRON4, TETRAHEDRON10, HEXAHEDRON8 = "tetrahedron4", "tetrahedron10", "hexahedron8"
ELEMENT_ORDER = (TRIANGLE3, TRIANGLE6, QUADRILATERAL4)
NODES_PER_ELEMENT = {TRIANGLE3: 3, TRIANGLE6: 6, QUADRILATERAL4: 4, LINE2: 2, LINE3: 3,
                     TETRAHEDRON4: 4, TETRAHEDRON10: 10, HEXAHEDRON8: 8}
# The spatial dimension of each domain cell type; the corners of each cell and facet type.
ELEMENT_DIMENSION = {TRIANGLE3: 2, TRIANGLE6: 2, QUADRILATERAL4: 2, TETRAHEDRON4: 3,
                     TETRAHEDRON10: 3, HEXAHEDRON8: 3}
CORNER_COUNT = {TRIANGLE3: 3, TRIANGLE6: 3, QUADRILATERAL4: 4, LINE2: 2, LINE3: 2,
                TETRAHEDRON4: 4, TETRAHEDRON10: 4, HEXAHEDRON8: 8}
VTK_CELL_TYPE = {TRIANGLE3: 5, TRIANGLE6: 22, QUADRILATERAL4: 9, TETRAHEDRON4: 10,
                 HEXAHEDRON8: 12}
# Gmsh element type numbers.
GMSH_AREA_TYPES = {2: TRIANGLE3, 9: TRIANGLE6, 3: QUADRILATERAL4}
GMSH_EDGE_TYPES = {1: LINE2, 8: LINE3}
# Nodes per Gmsh element type, for the types a .msh may hold (points, lines, areas, volumes).
GMSH_NODE_COUNTS = {15: 1, 1: 2, 8: 3, 26: 4, 27: 5, 28: 6, 2: 3, 9: 6, 3: 4, 10: 9, 16: 8,
                    20: 9, 21: 10, 22: 12, 23: 15, 4: 4, 5: 8, 6: 6, 7: 5, 11: 10, 12: 27,
                    13: 18, 14: 14, 17: 20, 18: 15, 19: 13, 29: 20, 30: 35, 31: 56}
GMSH_NAMES = {15: "point", 1: "2-node line", 8: "3-node line", 2: "3-node triangle",
              9: "6-node triangle", 3: "4-node quadrilateral", 10: "9-node quadrilateral",
              16: "8-node quadrilateral", 20: "9-node triangle", 21: "10-node triangle",
              4: "tetrahedron", 5: "hexahedron", 6: "prism", 7: "pyramid"}
# Reversal of a clockwise element into a counter-clockwise one (triangle6 midpoints follow).
REVERSED = {TRIANGLE3: [0, 2, 1], TRIANGLE6: [0, 2, 1, 5, 4, 3], QUADRILATERAL4: [0, 3, 2, 1]}


class ElementBlock:
    """Elements of one type: connectivity (element_count x nodes per element), node indices;
    tags (element_count) the elements' tags in the user's mesh, or None (then the elements are
    named by their 1-based position in the block)."""

    def __init__(self, element_type, connectivity, tags=None):
        self.type = element_type
        self.connectivity = np.asarray(connectivity, dtype=np.int64).reshape(
            -1, NODES_PER_ELEMENT[element_type])
        self.tags = tags

    def element_label(self, index):
        """How messages name element `index` of the block: its tag, or its 1-based position."""
        if self.tags is None:
            return "at position %d" % (index + 1)
        return "tag %d" % self.tags[index]


class BoundaryGroup:
    """A named boundary: its edges (edge_count x 2 or 3; endpoints first, then the midpoint), or
    in 3D its faces (face_count x 3 or 4 corners)."""

    def __init__(self, edge_type, connectivity):
        self.type = edge_type
        self.connectivity = np.asarray(connectivity, dtype=np.int64).reshape(
            -1, NODES_PER_ELEMENT[edge_type])

    def nodes(self):
        """Distinct node indices of the group, ascending."""
        return np.unique(self.connectivity)


class Mesh:
    """nodes (n x d), node_tags (n), blocks (list of ElementBlock), boundaries (name -> group);
    dimension d = 2 (plane) or 3 (solid, since protocol 2.4)."""

    def __init__(self, nodes, node_tags, blocks, boundaries):
        self.nodes = nodes
        self.node_tags = node_tags
        self.blocks = blocks
        self.boundaries = boundaries
        self.dimension = nodes.shape[1] if np.ndim(nodes) == 2 else 2

    def dof_count(self):
        return self.dimension * self.node_count()

    def node_count(self):
        return len(self.nodes)

    def element_count(self):
        return sum(len(block.connectivity) for block in self.blocks)


class _Raw:
    """A .msh file before extraction: Gmsh tags everywhere."""

    def __init__(self):
        self.physical_names = {}     # (dimension, physical tag) -> name
        self.entity_physicals = {}   # (dimension, entity tag) -> [physical tags]
        self.node_tags = []          # arrays of tags, in file order
        self.node_coordinates = []   # arrays (count x 3)
        self.element_blocks = []     # (dimension, entity tag, gmsh type, tags array (count x k))


class _Lines:
    """The lines of a text file with a cursor; errors name the source and the line."""

    def __init__(self, text, source):
        self.lines = text.splitlines()
        self.position = 0
        self.source = source

    def error(self, problem, line=None):
        line = self.position if line is None else line
        return InputError("%s: line %d: %s" % (self.source, line, problem))

    def next(self, section):
        if self.position >= len(self.lines):
            raise self.error("unexpected end of file in section $%s" % section)
        self.position += 1
        return self.lines[self.position - 1].strip()

    def numbers(self, section, kind=int):
        text = self.next(section)
        try:
            return [kind(word) for word in text.split()]
        except ValueError:
            raise self.error("expected numbers in section $%s, found '%s'" % (section, text[:80]))

    def block(self, section, count, columns):
        """`count` lines of at least `columns` numbers as a float array (count x columns)."""
        start = self.position
        if start + count > len(self.lines):
            raise self.error("unexpected end of file in section $%s" % section)
        self.position += count
        if count == 0:
            return np.zeros((0, columns))
        try:
            rows = [line.split() for line in self.lines[start:start + count]]
            return np.array([row[:columns] for row in rows], dtype=float).reshape(count, columns)
        except ValueError:
            raise self.error("malformed lines in section $%s" % section, start + 1)


def _skip_section(lines, name):
    while lines.next(name) != "$End" + name:
        pass


def _read_physical_names(lines, raw):
    count = lines.numbers("PhysicalNames")[0]
    for _ in range(count):
        text = lines.next("PhysicalNames")
        words = text.split(None, 2)
        if len(words) < 3:
            raise lines.error("malformed physical name '%s'" % text)
        raw.physical_names[(int(words[0]), int(words[1]))] = words[2].strip().strip('"')
    if lines.next("PhysicalNames") != "$EndPhysicalNames":
        raise lines.error("expected $EndPhysicalNames")


def _read_entities(lines, raw):
    counts = lines.numbers("Entities")
    for dimension, count in enumerate(counts[:4]):
        for _ in range(count):
            values = lines.numbers("Entities", float)
            # point: tag x y z n phys...; others: tag 6 box values n phys... m bounding...
            first = 4 if dimension == 0 else 7
            physical_count = int(values[first])
            physicals = [int(value) for value in values[first + 1:first + 1 + physical_count]]
            raw.entity_physicals[(dimension, int(values[0]))] = physicals
    if lines.next("Entities") != "$EndEntities":
        raise lines.error("expected $EndEntities")


def _read_nodes_41(lines, raw):
    block_count = lines.numbers("Nodes")[0]
    for _ in range(block_count):
        # entityDim entityTag parametric count; parametric coordinates follow x y z (unused)
        count = lines.numbers("Nodes")[3]
        tags = lines.block("Nodes", count, 1)[:, 0].astype(np.int64)
        coordinates = lines.block("Nodes", count, 3)
        raw.node_tags.append(tags)
        raw.node_coordinates.append(coordinates)
    if lines.next("Nodes") != "$EndNodes":
        raise lines.error("expected $EndNodes")


def _read_elements_41(lines, raw):
    block_count = lines.numbers("Elements")[0]
    for _ in range(block_count):
        dimension, entity, gmsh_type, count = lines.numbers("Elements")
        if gmsh_type not in GMSH_NODE_COUNTS:
            raise lines.error("unknown Gmsh element type %d" % gmsh_type)
        table = lines.block("Elements", count, 1 + GMSH_NODE_COUNTS[gmsh_type]).astype(np.int64)
        raw.element_blocks.append((dimension, entity, gmsh_type, table[:, 1:]))
    if lines.next("Elements") != "$EndElements":
        raise lines.error("expected $EndElements")


def _element_dimension(gmsh_type):
    if gmsh_type == 15:
        return 0
    if gmsh_type in (1, 8, 26, 27, 28):
        return 1
    if gmsh_type in (2, 3, 9, 10, 16, 20, 21, 22, 23):
        return 2
    return 3


def _read_nodes_22(lines, raw):
    count = lines.numbers("Nodes")[0]
    table = lines.block("Nodes", count, 4)
    raw.node_tags.append(table[:, 0].astype(np.int64))
    raw.node_coordinates.append(table[:, 1:4])
    if lines.next("Nodes") != "$EndNodes":
        raise lines.error("expected $EndNodes")


def _read_elements_22(lines, raw):
    """Elements `number type tag_count tags... nodes...`; tags[0] physical, tags[1] entity.
    An element repeated for several physical groups is kept once."""
    count = lines.numbers("Elements")[0]
    grouped = {}
    seen = set()
    for _ in range(count):
        values = lines.numbers("Elements")
        if len(values) < 3 or values[1] not in GMSH_NODE_COUNTS:
            raise lines.error("malformed element line")
        number, gmsh_type, tag_count = values[:3]
        tags = values[3:3 + tag_count]
        nodes = values[3 + tag_count:]
        if len(nodes) != GMSH_NODE_COUNTS[gmsh_type]:
            raise lines.error("element %d has %d nodes, expected %d" %
                              (number, len(nodes), GMSH_NODE_COUNTS[gmsh_type]))
        dimension = _element_dimension(gmsh_type)
        physical = tags[0] if tags else 0
        entity = tags[1] if len(tags) > 1 else physical
        physicals = raw.entity_physicals.setdefault((dimension, entity), [])
        if physical != 0 and physical not in physicals:
            physicals.append(physical)
        if (dimension, number) in seen:
            continue
        seen.add((dimension, number))
        grouped.setdefault((dimension, entity, gmsh_type), []).append(nodes)
    for (dimension, entity, gmsh_type), rows in grouped.items():
        raw.element_blocks.append((dimension, entity, gmsh_type, np.array(rows, dtype=np.int64)))
    if lines.next("Elements") != "$EndElements":
        raise lines.error("expected $EndElements")


def _read_format(lines):
    words = lines.next("MeshFormat").split()
    if len(words) < 3:
        raise lines.error("malformed $MeshFormat")
    version, binary = words[0], words[1]
    if binary != "0":
        raise lines.error("binary .msh files are not supported: save the mesh as ASCII "
                          "(gmsh -format msh41, or Mesh.Binary = 0)")
    if version not in ("4.1", "2.2"):
        raise lines.error("unsupported .msh version %s: give format 4.1 or 2.2" % version)
    if lines.next("MeshFormat") != "$EndMeshFormat":
        raise lines.error("expected $EndMeshFormat")
    return version


def parse_msh(text, source):
    """The raw content of an ASCII .msh (4.1 or 2.2)."""
    lines = _Lines(text, source)
    raw = _Raw()
    version = None
    while lines.position < len(lines.lines):
        header = lines.next("")
        if not header:
            continue
        if not header.startswith("$"):
            raise lines.error("expected a section header, found '%s'" % header[:80])
        section = header[1:]
        if section == "MeshFormat":
            version = _read_format(lines)
        elif version is None:
            raise lines.error("the file does not start with $MeshFormat: not a Gmsh .msh file")
        elif section == "PhysicalNames":
            _read_physical_names(lines, raw)
        elif section == "Entities" and version == "4.1":
            _read_entities(lines, raw)
        elif section == "Nodes":
            (_read_nodes_41 if version == "4.1" else _read_nodes_22)(lines, raw)
        elif section == "Elements":
            (_read_elements_41 if version == "4.1" else _read_elements_22)(lines, raw)
        else:
            _skip_section(lines, section)
    if version is None:
        raise InputError("%s: not a Gmsh .msh file (no $MeshFormat section)" % source)
    return raw


def _area_entities(raw):
    """The 2D entities to read, ascending: those in a 2D physical group, or all of them."""
    with_elements = {entity for dimension, entity, _, _ in raw.element_blocks if dimension == 2}
    grouped = {entity for (dimension, entity), physicals in raw.entity_physicals.items()
               if dimension == 2 and physicals}
    return sorted(grouped if grouped else with_elements)


def _area_elements(raw, source):
    """Gmsh node tags of the area elements per element type."""
    areas = {}
    entities = set(_area_entities(raw))
    for entity in sorted(entities):
        for dimension, block_entity, gmsh_type, tags in raw.element_blocks:
            if dimension != 2 or block_entity != entity:
                continue
            if gmsh_type not in GMSH_AREA_TYPES:
                raise InputError("%s: unsupported 2D element %s (Gmsh type %d); use 3-node or "
                                 "6-node triangles or 4-node quadrilaterals" %
                                 (source, GMSH_NAMES.get(gmsh_type, "unknown"), gmsh_type))
            areas.setdefault(GMSH_AREA_TYPES[gmsh_type], []).append(tags)
    if not areas:
        raise InputError("%s: contains no 2D elements (is the surface meshed, with a Physical "
                         "Surface?)" % source)
    return {kind: np.vstack(parts) for kind, parts in areas.items()}


def _boundary_edges(raw, source):
    """name -> (edge type, Gmsh node tags of its edges) for every 1D physical group."""
    groups = sorted({physical for (dimension, _), physicals in raw.entity_physicals.items()
                     if dimension == 1 for physical in physicals})
    edges = {}
    for group in groups:
        name = raw.physical_names.get((1, group)) or str(group)
        curves = sorted(entity for (dimension, entity), physicals in raw.entity_physicals.items()
                        if dimension == 1 and group in physicals)
        for curve in curves:
            for dimension, entity, gmsh_type, tags in raw.element_blocks:
                if dimension != 1 or entity != curve:
                    continue
                if gmsh_type not in GMSH_EDGE_TYPES:
                    raise InputError(
                        "%s: boundary '%s': unsupported 1D element %s (Gmsh type %d); use 2-node "
                        "or 3-node lines" % (source, name, GMSH_NAMES.get(gmsh_type, "unknown"),
                                             gmsh_type))
                kind = GMSH_EDGE_TYPES[gmsh_type]
                entry = edges.setdefault(name, (kind, []))
                if entry[0] != kind:
                    raise InputError("%s: boundary '%s' mixes 2-node and 3-node lines" %
                                     (source, name))
                entry[1].append(tags)
    return {name: (kind, np.vstack(parts)) for name, (kind, parts) in edges.items()}


def _twice_signed_areas(nodes, element_type, connectivity):
    corners = 4 if element_type == QUADRILATERAL4 else 3
    total = np.zeros(len(connectivity))
    for i in range(corners):
        a = nodes[connectivity[:, i]]
        b = nodes[connectivity[:, (i + 1) % corners]]
        total += a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1]
    return total


def _orient_counter_clockwise(nodes, node_tags, element_type, connectivity, source):
    areas = _twice_signed_areas(nodes, element_type, connectivity)
    degenerate = np.flatnonzero(areas == 0.0)
    if len(degenerate):
        raise InputError("%s: a %s element at node %d has zero area" %
                         (source, element_type, node_tags[connectivity[degenerate[0], 0]]))
    clockwise = areas < 0.0
    connectivity[clockwise] = connectivity[clockwise][:, REVERSED[element_type]]
    return connectivity


def _node_table(raw, used, source):
    """Coordinates (len(used) x 3) of the Gmsh node tags `used` (ascending)."""
    if not raw.node_tags:
        raise InputError("%s: an element uses a node that is not defined" % source)
    tags = np.concatenate(raw.node_tags)
    coordinates = np.vstack(raw.node_coordinates)
    order = np.argsort(tags, kind="stable")
    position = np.searchsorted(tags[order], used)
    position = np.minimum(position, len(tags) - 1)
    found = tags[order][position] == used
    if not np.all(found):
        raise InputError("%s: an element uses a node that is not defined" % source)
    extent = np.max(np.abs(coordinates)) if coordinates.size else 0.0
    table = coordinates[order][position]
    off_plane = np.flatnonzero(np.abs(table[:, 2]) > 1e-10 * extent)
    if len(off_plane):
        k = off_plane[0]
        raise InputError("%s: node %d has z = %g: the mesh must lie in the z = 0 plane" %
                         (source, used[k], table[k, 2]))
    return table


def extract_mesh(raw, source):
    """The Mesh of a parsed .msh (see the module comment)."""
    if not any(raw.entity_physicals.values()):
        raise InputError("%s: defines no physical groups: add a Physical Surface for the body and "
                         "Physical Curves for its boundaries" % source)
    areas = _area_elements(raw, source)
    edges = _boundary_edges(raw, source)
    used = np.unique(np.concatenate([tags.ravel() for tags in areas.values()] +
                                    [tags.ravel() for _, tags in edges.values()]))
    table = _node_table(raw, used, source)
    nodes = np.ascontiguousarray(table[:, :2])

    def indices(tags):
        return np.searchsorted(used, tags).astype(np.int64)

    blocks = []
    for kind in ELEMENT_ORDER:
        if kind in areas:
            connectivity = indices(areas[kind])
            _orient_counter_clockwise(nodes, used, kind, connectivity, source)
            blocks.append(ElementBlock(kind, connectivity))
    boundaries = {name: BoundaryGroup(kind, indices(tags))
                  for name, (kind, tags) in sorted(edges.items())}
    return Mesh(nodes, used.astype(np.int64), blocks, boundaries)


def read_msh_text(text, source):
    """The mesh of the text of an ASCII .msh file; `source` names it in errors."""
    return extract_mesh(parse_msh(text, source), source)


def _unusable_temporary_directory(source, directory, problem):
    return RequestError(
        "INTERNAL", "%s: cannot write the mesh to a temporary file in '%s' (%s): the server's "
        "temporary directory (TMPDIR, else /tmp) is not writable or is full; give the server "
        "process a writable TMPDIR (in a container: a tmpfs or emptyDir volume at /tmp)" %
        (source, directory, problem))


@contextlib.contextmanager
def _temporary_directory(prefix, source):
    """A fresh directory under the temporary directory (TMPDIR, else /tmp), removed on exit.
    An OSError creating it or raised inside the block (writing the files for gmsh, reading its
    output) becomes the RequestError INTERNAL of _unusable_temporary_directory."""
    try:
        directory = tempfile.mkdtemp(prefix=prefix)
    except OSError as error:  # FileNotFoundError when no candidate directory is usable
        raise _unusable_temporary_directory(
            source, os.environ.get("TMPDIR") or tempfile.tempdir or "/tmp",
            error.strerror or error)
    try:
        yield directory
    except OSError as error:
        raise _unusable_temporary_directory(source, os.path.dirname(directory),
                                            error.strerror or error)
    finally:
        shutil.rmtree(directory, ignore_errors=True)


def _format_size(size):
    return repr(float(size))


def _run_gmsh(arguments, source, action, input_path):
    """Runs the gmsh command-line tool; any "Error" line or a failed exit is an InputError."""
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        raise InputError("%s: the gmsh command-line tool is not installed (needed for %s; "
                         "apt-get install gmsh)" % (source, action))
    completed = subprocess.run([gmsh] + arguments + ["-v", "2", "-nt", "1"], capture_output=True,
                               text=True, check=False, stdin=subprocess.DEVNULL, timeout=3600)
    log = (completed.stdout + "\n" + completed.stderr).splitlines()
    errors = [line.split(":", 1)[1].strip() for line in log if line.startswith("Error")]
    errors = [error.replace(str(input_path), source) for error in errors if error]
    if errors or completed.returncode != 0:
        problem = "; ".join(dict.fromkeys(errors)) or "gmsh exited with status %d" % (
            completed.returncode)
        raise InputError("%s: %s failed: %s" % (source, action, problem))


def mesh_geo_file(geo_path, source, size=0.0, element_order=1, recombine=False):
    """Meshes a .geo in 2D with the gmsh command-line tool (`-setnumber h SIZE` when size > 0,
    `-order N`, Mesh.RecombineAll = 1 when recombine) and returns the .msh text (format 4.1)."""
    with _temporary_directory("robin-subdomain-py-mesh-", source) as directory:
        output = os.path.join(directory, "mesh.msh")
        arguments = [str(geo_path), "-2", "-order", str(element_order), "-format", "msh41",
                     "-o", output]
        if size > 0.0:
            arguments[1:1] = ["-setnumber", "h", _format_size(size)]
        if recombine:
            arguments[1:1] = ["-string", "Mesh.RecombineAll = 1;"]
        _run_gmsh(arguments, source, "meshing", geo_path)
        return pathlib.Path(output).read_text()


def _is_native_msh(content):
    """True for an ASCII .msh of format 4.1 or 2.2 (read here); other versions and binary
    files are converted by gmsh first."""
    head = content[:200].split(b"\n")
    if len(head) < 2 or head[0].strip() != b"$MeshFormat":
        return True  # not a .msh at all: the reader reports it
    words = head[1].split()
    return len(words) >= 2 and words[0] in (b"4.1", b"2.2") and words[1] == b"0"


def read_msh_bytes(content, source):
    """The mesh of the bytes of a .msh file of any version Gmsh reads, ASCII or binary."""
    if not _is_native_msh(content):
        with _temporary_directory("robin-subdomain-py-msh-", source) as directory:
            original = os.path.join(directory, "original.msh")
            converted = os.path.join(directory, "converted.msh")
            pathlib.Path(original).write_bytes(content)
            _run_gmsh([original, "-0", "-save_all", "-format", "msh41", "-o", converted], source,
                      "reading", original)
            content = pathlib.Path(converted).read_bytes()
    try:
        text = content.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError("%s: not a Gmsh .msh file (not text)" % source)
    return read_msh_text(text, source)


def read_mesh(path, source, size=0.0, element_order=1, recombine=False):
    """The mesh of a .msh or .geo file (by extension, case-insensitive)."""
    path = pathlib.Path(path)
    extension = path.suffix.lower()
    if extension not in (".msh", ".geo"):
        raise InputError("%s: unsupported extension '%s': give a .msh or .geo file" %
                         (source, extension))
    if not path.is_file():
        raise InputError("%s: the file does not exist or is not a regular file" % source)
    if extension == ".geo":
        return read_msh_text(mesh_geo_file(path, source, size, element_order, recombine), source)
    return read_msh_bytes(path.read_bytes(), source)
