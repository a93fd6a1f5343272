"""Protocol 2.5 on the Python server, without a socket (the server runs in this process):
  - peak_resident_bytes in InterfaceDescription, the Acknowledge of AssignContact and
    FieldsReply: positive, never below the resident size this test read from /proc/self/status
    before the request (VmRSS) and never above the high-water mark it reads after the reply
    (VmHWM), and not decreasing from one reply to the next;
  - the version rule of robin-subdomain: the server's own minor version decides, not the
    request's (a request saying 2.4 or 2.0 gets the 2.5 fields; a server started with
    protocol_minor 4, robin-subdomain-py --protocol-minor 4, sends none and ignores
    omit_fields_from_reply);
  - FieldsRequest.omit_fields_from_reply with write_directory: no mesh and no fields in the
    reply, the resultants, written_file, stage_times, dimension (3 for a solid body) and
    peak_resident_bytes kept, and the written file byte for byte the one written without the
    flag; without write_directory INVALID_ARGUMENT naming the field, nothing written;
  - resident_memory.peak_resident_bytes: VmHWM of a status file, else ru_maxrss in kibibytes
    (Linux), else 0.
"""

import pathlib
import resource
import shutil
import tempfile
import unittest
from unittest import mock

import support
from robin_subdomain import resident_memory
from robin_subdomain.proto_module import load_protocol
from test_protocol import ServerTestCase, request, setup_body

protocol = load_protocol()
# The FieldsReply fields protocol 2.5 leaves out for omit_fields_from_reply (docs/protocol.md).
MESH_AND_FIELDS = ("node_coordinates", "node_tags", "cell_types", "cell_offsets", "connectivity",
                   "point_fields", "cell_fields", "boundaries")


def status_kibibytes(key):
    """The value of `key` (e.g. "VmHWM") in kB in this process's /proc/self/status, read here
    independently of the server; None when absent."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                name, _, value = line.partition(":")
                if name == key:
                    number, unit = value.split()
                    assert unit == "kB", line
                    return int(number)
    except OSError:
        return None
    return None


def solid_body():
    """A box of 4 x 2 x 2 cubes of tetrahedra, bottom clamped, the top side z1 in contact."""
    nodes, elements, sides = support.box_tetrahedra((4, 2, 2), (2.0, 1.0, 1.0), 0.2)
    message = protocol.SetupBody(body_name="block", contact_boundaries=["z1"],
                                 young_modulus=1000.0, poisson_ratio=0.3)
    message.mesh.CopyFrom(support.solid_mesh_data(protocol, nodes, "TETRAHEDRON4", elements,
                                                  sides))
    message.dirichlet.add(boundary="z0", x=0.0, y=0.0, z=-0.001)
    return message


@unittest.skipIf(status_kibibytes("VmHWM") is None, "no VmHWM in /proc/self/status")
class PeakResidentSize(ServerTestCase):
    def measured_reply(self, data, reply_field):
        """(the reply's `reply_field`, VmRSS before the request, VmHWM after the reply), the
        sizes in bytes."""
        resident_before = 1024 * status_kibibytes("VmRSS")
        reply = self.ask(data)
        high_water_mark_after = 1024 * status_kibibytes("VmHWM")
        self.assertEqual(reply.WhichOneof("content"), reply_field, reply)
        return getattr(reply, reply_field), resident_before, high_water_mark_after

    def test_the_long_requests_report_the_peak_resident_size(self):
        """Also for requests that say 2.4 and 2.0: the server's minor version decides."""
        for request_minor in (5, 4, 0):
            with self.subTest(request_minor=request_minor):
                self.server = self.make_server()
                interface, before, after = self.measured_reply(
                    request(minor=request_minor, setup_body=setup_body()), "interface")
                measurements = [(interface, before, after)]
                assign = support.node_to_node_assignment(protocol, interface)
                measurements.append(self.measured_reply(
                    request(minor=request_minor, assign_contact=assign), "acknowledge"))
                measurements.append(self.measured_reply(
                    request(minor=request_minor, fields=protocol.FieldsRequest(
                        contact_force=[0.0] * len(interface.node_ids))), "fields_reply"))
                previous = 0
                for message, before, after in measurements:
                    peak = message.peak_resident_bytes
                    self.assertGreater(peak, 0, message.DESCRIPTOR.name)
                    self.assertLessEqual(before, peak, message.DESCRIPTOR.name)
                    self.assertLessEqual(peak, after, message.DESCRIPTOR.name)
                    self.assertGreaterEqual(peak, previous, message.DESCRIPTOR.name)
                    previous = peak

    def test_a_server_speaking_2_4_reports_none(self):
        self.server = self.make_server(protocol_minor=4)
        interface = self.ask(request(minor=4, setup_body=setup_body())).interface
        count = len(interface.node_ids)
        self.assertGreater(count, 0)
        assign = support.node_to_node_assignment(protocol, interface)
        acknowledge = self.ask(request(minor=4, assign_contact=assign)).acknowledge
        self.assertEqual(acknowledge.state, "ready")
        fields = self.ask(request(minor=4, fields=protocol.FieldsRequest(
            contact_force=[0.0] * count))).fields_reply
        self.assertEqual(len(fields.point_fields), 6)
        for message in (interface, acknowledge, fields):
            self.assertEqual(message.peak_resident_bytes, 0, message.DESCRIPTOR.name)
            self.assertNotIn("peak_resident_bytes",
                             [descriptor.name for descriptor, _ in message.ListFields()])


class OmittedFields(ServerTestCase):
    def setUp(self):
        self.root = pathlib.Path(tempfile.mkdtemp(prefix="robin-py-omitted-"))
        self.addCleanup(shutil.rmtree, self.root)
        self.server = self.make_server(output_root=str(self.root))

    def set_up(self, body, assignment):
        interface = self.ask(request(setup_body=body)).interface
        self.assertEqual(self.ask(request(assign_contact=assignment(protocol, interface)))
                         .acknowledge.state, "ready")
        return len(interface.node_ids)

    def fields(self, count, write_directory="", omit=False):
        force = [0.5 + 0.1 * k for k in range(count)]
        return self.ask(request(minor=5, fields=protocol.FieldsRequest(
            contact_force=force, write_directory=write_directory,
            omit_fields_from_reply=omit)))

    def expect_same_file_and_resultants(self, count, dimension):
        full = self.fields(count, "full").fields_reply
        omitted = self.fields(count, "omitted", omit=True).fields_reply
        for name in MESH_AND_FIELDS:
            self.assertEqual(len(getattr(omitted, name)), 0, name)
            self.assertGreater(len(getattr(full, name)), 0, name)
        self.assertEqual(omitted.written_file, str(self.root / "omitted" / (self.body_name +
                                                                             ".vtu")))
        written = pathlib.Path(omitted.written_file).read_bytes()
        self.assertGreater(len(written), 1000)
        self.assertEqual(written, pathlib.Path(full.written_file).read_bytes())
        self.assertEqual(list(omitted.reaction_resultant), list(full.reaction_resultant))
        self.assertEqual(list(omitted.applied_force), list(full.applied_force))
        self.assertEqual(len(omitted.reaction_resultant), dimension)
        self.assertEqual([entry.stage for entry in omitted.stage_times], ["fields"])
        self.assertEqual(omitted.dimension, full.dimension)
        self.assertEqual(omitted.dimension, 0 if dimension == 2 else 3)  # 0: absent, plane
        self.assertGreater(omitted.peak_resident_bytes, 0)

    def test_a_plane_body_without_mesh_and_fields_and_the_same_file(self):
        self.body_name = "lower"
        count = self.set_up(setup_body(), support.node_to_node_assignment)
        self.expect_same_file_and_resultants(count, 2)

    def test_a_solid_body_keeps_its_dimension(self):
        self.body_name = "block"
        count = self.set_up(solid_body(), support.solid_node_to_node_assignment)
        self.expect_same_file_and_resultants(count, 3)

    def test_without_write_directory_it_is_invalid_argument(self):
        count = self.set_up(setup_body(), support.node_to_node_assignment)
        message = self.expect_error(request(minor=5, fields=protocol.FieldsRequest(
            contact_force=[0.0] * count, omit_fields_from_reply=True)), "INVALID_ARGUMENT",
            "ready")
        self.assertEqual(message, "body 'lower': FieldsRequest.omit_fields_from_reply is set "
                                  "without write_directory: the fields would go nowhere")
        self.assertEqual(list(self.root.iterdir()), [])

    def test_a_server_speaking_2_4_ignores_the_flag(self):
        self.server = self.make_server(output_root=str(self.root), protocol_minor=4)
        count = self.set_up(setup_body(), support.node_to_node_assignment)
        reply = self.fields(count, "flagged", omit=True).fields_reply
        full = self.fields(count, "full").fields_reply
        for name in MESH_AND_FIELDS:
            self.assertGreater(len(getattr(reply, name)), 0, name)
        self.assertEqual(list(reply.point_fields), list(full.point_fields))
        self.assertEqual(pathlib.Path(reply.written_file).read_bytes(),
                         pathlib.Path(full.written_file).read_bytes())
        without_directory = self.fields(count, omit=True).fields_reply
        self.assertEqual(list(without_directory.node_coordinates), list(full.node_coordinates))
        self.assertEqual(without_directory.written_file, "")


class ResidentMemory(unittest.TestCase):
    def status_file(self, text):
        directory = tempfile.mkdtemp(prefix="robin-py-status-")
        self.addCleanup(shutil.rmtree, directory)
        path = pathlib.Path(directory) / "status"
        path.write_text(text)
        return str(path)

    def test_the_high_water_mark_of_the_status_file(self):
        path = self.status_file("Name:\tpython3\nVmPeak:\t  999999 kB\nVmHWM:\t   12345 kB\n"
                                "VmRSS:\t   11111 kB\n")
        self.assertEqual(resident_memory.peak_resident_bytes(path), 12345 * 1024)

    def test_without_a_usable_status_file_the_maximum_resident_size_of_getrusage(self):
        for path in (str(pathlib.Path(tempfile.gettempdir()) / "robin-no-such-status"),
                     self.status_file("Name:\tpython3\nVmRSS:\t 11111 kB\n"),
                     self.status_file("VmHWM:\t 12345 MB\n")):
            with self.subTest(path=path):
                before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
                measured = resident_memory.peak_resident_bytes(path)
                after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
                self.assertGreater(before, 0)
                self.assertTrue(1024 * before <= measured <= 1024 * after, measured)

    def test_zero_when_nothing_is_known(self):
        missing = str(pathlib.Path(tempfile.gettempdir()) / "robin-no-such-status")
        with mock.patch.object(resident_memory.sys, "platform", "darwin"):
            self.assertEqual(resident_memory.peak_resident_bytes(missing), 0)


if __name__ == "__main__":
    unittest.main()
