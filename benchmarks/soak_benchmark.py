#!/usr/bin/python3
"""Memory of one subdomain server over thousands of runs (docs/benchmarks.md, "Soak").

Starts one server (robin-subdomain, or robin-subdomain-py with --python), then repeats a whole
run on it: SetupBody (a structured mesh of the unit square sent as MeshData, 2 n^2 triangles),
AssignContact (node-to-node rows on the top edge), one ContactSolveRequest, a FieldsRequest and
EndRun. Every `--every` setups it prints the server's resident set size (VmRSS of
/proc/PID/status). A server that keeps nothing between runs has a flat RSS after warm-up.

Usage: /usr/bin/python3 benchmarks/soak_benchmark.py [--build build] [--setups 2400] [--every 200]
                                                    [--cells 20] [--python]
"""

import argparse
import os
import pathlib
import subprocess
import sys
import time

import numpy as np
import zmq

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


def setup_request(mesh):
    body = protocol.SetupBody(body_name="soak", model=protocol.PLANE_STRAIN, young_modulus=1000.0,
                              poisson_ratio=0.3)
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


def resident_megabytes(pid):
    with open("/proc/%d/status" % pid) as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def start_server(arguments):
    if arguments.python:
        command = [sys.executable, str(repository / "python" / "robin-subdomain-py")]
    else:
        command = [str(repository / arguments.build / "bin" / "robin-subdomain")]
    server = subprocess.Popen(command + ["--listen", "tcp://127.0.0.1:*", "--log-level", "warn"],
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
    arguments = parser.parse_args()
    server, endpoint = start_server(arguments)
    socket = zmq.Context.instance().socket(zmq.DEALER)
    socket.connect(endpoint)
    mesh = square_mesh(arguments.cells)
    print("server: %s, %d setups of %d triangles, RSS every %d" % (
        "robin-subdomain-py" if arguments.python else "robin-subdomain", arguments.setups,
        2 * arguments.cells ** 2, arguments.every))
    print("| setups | RSS (MiB) | seconds |")
    print("|---|---|---|")
    start, request_id = time.time(), 0
    try:
        for setup in range(1, arguments.setups + 1):
            request_id += 1
            interface = exchange(socket, request_id, setup_body=setup_request(mesh)).interface
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
