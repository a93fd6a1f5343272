#!/usr/bin/python3
"""Memory of one subdomain server over thousands of runs (docs/benchmarks.md, "Soak").

Starts one server (robin-subdomain, or robin-subdomain-py with --python), then repeats a whole
run on it: SetupBody (a structured mesh of the unit square sent as MeshData, 2 n^2 triangles),
AssignContact (node-to-node rows on the top edge), one ContactSolveRequest, a FieldsRequest and
EndRun. Every `--every` setups it prints the server's resident set size (VmRSS of
/proc/PID/status). A server that keeps nothing between runs has a flat RSS after warm-up.
With --mesh-path the same mesh is written once as square.msh (MSH 2.2) into a temporary data
directory given to the server (--data-directory), and every SetupBody names it in mesh_path
instead of carrying MeshData: the server reads the file with Gmsh (robin-subdomain) or its own
reader (robin-subdomain-py) at every setup.

Usage: /usr/bin/python3 benchmarks/soak_benchmark.py [--build build] [--setups 2400] [--every 200]
                                                    [--cells 20] [--python] [--mesh-path]
"""

import argparse
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np
import zmq

from benchmark_support import resident_megabytes, table_rule, table_row, tool_directory

repository = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(repository / "python"))
from robin_subdomain.proto_module import load_protocol  # noqa: E402

protocol = load_protocol()


def square_mesh(cells):
    """MeshData of [0, 1]^2 in 2 cells^2 counter-clockwise triangles; boundaries bottom, top."""
    ticks = np.linspace(0.0, 1.0, cells + 1)
    x, y = np.meshgrid(ticks, ticks)
    data = protocol.MeshData(dimension=2, source="soak square")
    data.coordinates.extend(np.column_stack([x.ravel(), y.ravel()]).ravel().tolist())
    index = lambda i, j: j * (cells + 1) + i  # noqa: E731
    block = data.cells.add(type=protocol.TRIANGLE3)
    for j in range(cells):
        for i in range(cells):
            a, b, c, d = index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)
            block.connectivity.extend([a, b, c, a, c, d])
    for name, row in (("bottom", 0), ("top", cells)):
        boundary = data.boundaries.add(name=name)
        boundary.segments.type = protocol.LINE2
        for i in range(cells):
            boundary.segments.connectivity.extend([index(i, row), index(i + 1, row)])
    return data


def write_msh(mesh, path):
    """`mesh` (MeshData from square_mesh) as an MSH 2.2 file: physical curves bottom (1) and top
    (2), physical surface body (3)."""
    coordinates = np.reshape(list(mesh.coordinates), (-1, 2))
    triangles = np.reshape(list(mesh.cells[0].connectivity), (-1, 3))
    lines = [(tag, np.reshape(list(boundary.segments.connectivity), (-1, 2)))
             for tag, boundary in enumerate(mesh.boundaries, start=1)]
    with open(path, "w") as stream:
        stream.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n%d\n"
                     % (len(lines) + 1))
        for tag, boundary in enumerate(mesh.boundaries, start=1):
            stream.write('1 %d "%s"\n' % (tag, boundary.name))
        stream.write('2 %d "body"\n$EndPhysicalNames\n$Nodes\n%d\n'
                     % (len(lines) + 1, len(coordinates)))
        for number, (x, y) in enumerate(coordinates, start=1):
            stream.write("%d %.17g %.17g 0\n" % (number, x, y))
        elements = [(1, tag, segment) for tag, segments in lines for segment in segments]
        elements += [(2, len(lines) + 1, triangle) for triangle in triangles]
        stream.write("$EndNodes\n$Elements\n%d\n" % len(elements))
        for number, (kind, tag, nodes) in enumerate(elements, start=1):
            stream.write("%d %d 2 %d %d %s\n" % (number, kind, tag, tag,
                                                 " ".join(str(node + 1) for node in nodes)))
        stream.write("$EndElements\n")


def setup_request(mesh, mesh_path=None):
    body = protocol.SetupBody(body_name="soak", model=protocol.PLANE_STRAIN, young_modulus=1000.0,
                              poisson_ratio=0.3)
    if mesh_path:
        body.mesh_path = mesh_path
    else:
        body.mesh.CopyFrom(mesh)
    support = body.dirichlet.add(boundary="bottom")
    support.x, support.y = 0.0, 0.01
    body.contact_boundaries.append("top")
    return body


def exchange(socket, request_id, **content):
    envelope = protocol.Envelope(request_id=request_id, **content)
    envelope.version.major, envelope.version.minor = 2, 0
    socket.send_multipart([b"", envelope.SerializeToString()])
    frames = socket.recv_multipart()
    reply = protocol.Envelope()
    reply.ParseFromString(frames[-1])
    if reply.HasField("error"):
        raise RuntimeError("server error: %s" % reply.error.message)
    return reply


def start_server(arguments, data_directory=None):
    if arguments.python:
        command = [sys.executable, str(repository / "python" / "robin-subdomain-py")]
    else:
        # --build is relative to the repository, not to the current directory
        command = [str(tool_directory(repository / arguments.build, ("robin-subdomain",))
                       / "robin-subdomain")]
    command += ["--listen", "tcp://127.0.0.1:*", "--log-level", "warn"]
    if data_directory:
        command += ["--data-directory", data_directory]
    server = subprocess.Popen(command,
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    line = server.stdout.readline().strip()
    if not line.startswith("listening on "):
        server.kill()
        raise RuntimeError("the server did not start: %r" % line)
    return server, line[len("listening on "):]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--setups", type=int, default=2400)
    parser.add_argument("--every", type=int, default=200)
    parser.add_argument("--cells", type=int, default=20)
    parser.add_argument("--python", action="store_true")
    parser.add_argument("--mesh-path", action="store_true",
                        help="send mesh_path (a .msh in the server's data directory), not MeshData")
    arguments = parser.parse_args()
    mesh = square_mesh(arguments.cells)
    with tempfile.TemporaryDirectory(prefix="robin-soak-") as data_directory:
        mesh_path = None
        if arguments.mesh_path:
            mesh_path = "square.msh"
            write_msh(mesh, os.path.join(data_directory, mesh_path))
        soak(arguments, mesh, mesh_path, data_directory if mesh_path else None)


def soak(arguments, mesh, mesh_path, data_directory):
    server, endpoint = start_server(arguments, data_directory)
    socket = zmq.Context.instance().socket(zmq.DEALER)
    socket.connect(endpoint)
    print("server: %s, %d setups of %d triangles (%s), RSS every %d" % (
        "robin-subdomain-py" if arguments.python else "robin-subdomain", arguments.setups,
        2 * arguments.cells ** 2, "mesh_path " + mesh_path if mesh_path else "MeshData",
        arguments.every))
    print(table_row(["setups", "RSS (MiB)", "seconds"]))
    print(table_rule(3))
    start, request_id = time.time(), 0
    try:
        for setup in range(1, arguments.setups + 1):
            request_id += 1
            interface = exchange(socket, request_id,
                                 setup_body=setup_request(mesh, mesh_path)).interface
            count = len(interface.node_ids)
            assign = protocol.AssignContact(row_offsets=range(0, 2 * count + 1, 2),
                                            node_ids=np.repeat(list(interface.node_ids), 2).tolist(),
                                            components=[0, 1] * count,
                                            values=list(interface.normals),
                                            weights=list(interface.weights))
            exchange(socket, request_id + 1, assign_contact=assign)
            exchange(socket, request_id + 2, contact_solve=protocol.ContactSolveRequest(
                iteration=1, obstacle=[0.005] * count))
            exchange(socket, request_id + 3, fields=protocol.FieldsRequest(
                contact_force=[0.0] * count))
            exchange(socket, request_id + 4, end_run=protocol.EndRun())
            request_id += 4
            if setup % arguments.every == 0 or setup == 1:
                print("| %d | %.1f | %.1f |" % (setup, resident_megabytes(server.pid),
                                               time.time() - start), flush=True)
    finally:
        server.kill()
        server.wait()


if __name__ == "__main__":
    main()
