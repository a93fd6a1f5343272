"""The subdomain server's protocol state machine (proto/robin.proto), free of transport: a
serialized request Envelope in, a serialized reply Envelope out. One body at a time. The states,
transitions and error codes are those of the C++ server (subdomain/server/subdomain_server.hpp):

  awaiting_setup       no body
  awaiting_assignment  body assembled and factorized (SetupBody done); + AssignContact
  ready                contact nodes assigned; + AssignContact, ContactSolveRequest,
                       CorrectionRequest, NeumannSolveRequest, FieldsRequest
Hello, SetupBody, EndRun and Shutdown are accepted in every state. SetupBody discards the
previous body first (a failed SetupBody leaves awaiting_setup); a refused AssignContact keeps the
state and the previous assignment; EndRun -> awaiting_setup; Shutdown keeps the state and sets
shutdown_requested.

Protocol 2.0: the mesh arrives as data (SetupBody.mesh, mesh_data.py) or names a file under the
data directory the operator gave at start (mesh_path, --data-directory); InterfaceDescription
describes every contact boundary (dimension, fixed components, surfaces of segments);
AssignContact carries a general sparse constraint operator B in compressed rows
(assignment.py); FieldsRequest.write_directory is a relative directory under the output root
given at start (--output-root), refused without one. No reply carries a non-finite number: a
contact solve, correction, Neumann solve or fields reply that would is replaced by
Error(SOLVER_FAILURE) naming the body and the request (the state is unchanged).

Since 2.1: SetLoadFactor, in awaiting_assignment and ready (state unchanged), scales every load
and prescribed displacement of the body (quasi-static load steps without a new SetupBody); a
factor that is not finite or above 1e6 in magnitude is BAD_INPUT.

Since 1.1: besides the core capabilities the server announces the optional "neumann_solve"
(NeumannSolveRequest: u_N = B K^-1 (f - B' lambda) for a given contact force lambda).

Since 1.2, runs (Envelope.run_id): a successful SetupBody records its request's run_id with the
body (any previous body is discarded whichever run it belonged to). While the body is held,
AssignContact, ContactSolveRequest, CorrectionRequest, NeumannSolveRequest, FieldsRequest and
EndRun whose run_id is non-empty and differs from a non-empty recorded one are refused with
WRONG_STATE ("... now belongs to another run ..."), the state unchanged: another coordinator set
the body up. An empty run_id (a 1.0 or 1.1 coordinator) is served as before. Replies echo the
request's run_id.

Since 2.4, solid bodies: a MeshData of dimension 3 with TETRAHEDRON4 or HEXAHEDRON8 cells and
TRIANGLE3 or QUADRILATERAL4 boundary faces is served like a plane body (InterfaceDescription and
FieldsReply with dimension 3, three components per vector); TETRAHEDRON10 cells and TRIANGLE6
faces are refused with UNSUPPORTED naming the cell type (mesh_data.py).

Since 2.5: InterfaceDescription, the Acknowledge of AssignContact and FieldsReply carry
peak_resident_bytes, the process's peak resident set size (resident_memory.py); a FieldsRequest
with omit_fields_from_reply and write_directory is answered without the mesh and the fields
(the file written as without the flag), and the flag without write_directory is
INVALID_ARGUMENT. As in robin-subdomain, the server's own minor version decides, not the
request's: a 2.4 client does not know these fields (proto3 skips them) and cannot set the flag.
A server made with protocol_minor below 5 (robin-subdomain-py --protocol-minor, testing only)
sends no peak_resident_bytes and ignores the flag, as a 2.4 server does.

Every reply echoes the request_id and carries version (protocol_major, protocol_minor). Failures
are Error replies: MALFORMED_MESSAGE (not an Envelope, no version, no content), VERSION_MISMATCH
(another major version, e.g. a 1.x request), WRONG_STATE (also for another run's run_id),
INVALID_ARGUMENT (sizes, the constraint operator, non-finite values, a refused write_directory,
omit_fields_from_reply without write_directory), BAD_INPUT (the body definition, its mesh, a
refused mesh_path), SINGULAR_BODY, SOLVER_FAILURE (a reply would carry a non-finite number),
UNSUPPORTED (a reply sent as a request, a request unknown to this version), INTERNAL (anything
else).
"""

import logging
import time

import numpy as np
from google.protobuf.message import DecodeError

from . import SERVER_NAME
from .assignment import decode_assign_contact
from .body import Body
from .errors import InputError, RequestError, SingularBodyError
from .fields import body_fields, vtu_bytes
from .mesh import VTK_CELL_TYPE
from .mesh_data import quoted
from .paths import PathRefused, check_output_directory, write_under_root
from .resident_memory import peak_resident_bytes
from .setup_decoding import decode_setup_body

PROTOCOL_MAJOR, PROTOCOL_MINOR = 2, 5
MAXIMUM_LOAD_FACTOR = 1e6         # SetLoadFactor: a larger magnitude is BAD_INPUT
AWAITING_SETUP, AWAITING_ASSIGNMENT, READY = "awaiting_setup", "awaiting_assignment", "ready"
REQUESTS = ("hello", "setup_body", "assign_contact", "contact_solve", "correction",
            "neumann_solve", "fields", "end_run", "shutdown", "set_load_factor")
CAPABILITIES = ("contact_solve", "correction_solve", "fields", "neumann_solve")
# The FieldsReply fields left out for FieldsRequest.omit_fields_from_reply (protocol 2.5).
OMITTED_FIELDS = ("node_coordinates", "node_tags", "cell_types", "cell_offsets", "connectivity",
                  "point_fields", "cell_fields", "boundaries")


def _add_stage_times(stage_times, stages):
    """Appends a StageTime (protocol 2.2) per (stage name, seconds) to a reply's stage_times."""
    for stage, seconds in stages:
        entry = stage_times.add()
        entry.stage = stage
        entry.seconds = seconds


class _Record:
    """What the log line of a request says."""

    def __init__(self):
        self.type = "(unparsed message)"
        self.body = ""
        self.iteration = ""
        self.outcome = "ok"
        self.failed = False
        self.start = time.perf_counter()   # the request's bytes received


def _checked_vector(values, size, field, body_name):
    """A per-constraint vector of a request: its length and finiteness."""
    if len(values) != size:
        raise RequestError("INVALID_ARGUMENT",
                           "%s has %d values for the %d constraints of body '%s' (the rows of "
                           "AssignContact)" % (field, len(values), size, body_name))
    vector = np.array(values, dtype=float)
    bad = np.flatnonzero(~np.isfinite(vector))
    if len(bad):
        raise RequestError("INVALID_ARGUMENT", "%s[%d] of body '%s' is not a finite number" %
                           (field, bad[0], body_name))
    return vector


def first_non_finite(message, prefix):
    """(field, value) of the first NaN or infinite number in `message` and the messages it
    holds, the field named from `prefix` (e.g. "ContactSolveResult.normal_trace[3]"); None when
    every number is finite."""
    for descriptor, value in message.ListFields():
        name = "%s.%s" % (prefix, descriptor.name)
        repeated = descriptor.label == descriptor.LABEL_REPEATED
        if descriptor.type == descriptor.TYPE_MESSAGE:
            for index, item in enumerate(value if repeated else [value]):
                found = first_non_finite(item, name + ("[%d]" % index if repeated else ""))
                if found:
                    return found
        elif descriptor.cpp_type in (descriptor.CPPTYPE_DOUBLE, descriptor.CPPTYPE_FLOAT):
            numbers = np.array(value if repeated else [value], dtype=float)
            bad = np.flatnonzero(~np.isfinite(numbers))
            if len(bad):
                return (name + ("[%d]" % bad[0] if repeated else ""), numbers[bad[0]])
    return None


# The body size limit's default, robin-subdomain's (--max-dofs).
DEFAULT_MAXIMUM_DOFS = 20000000


class SubdomainProtocol:
    def __init__(self, protocol, name="", protocol_major=PROTOCOL_MAJOR, logger=None,
                 data_directory=None, output_root=None, maximum_dofs=DEFAULT_MAXIMUM_DOFS,
                 protocol_minor=PROTOCOL_MINOR):
        """`protocol_major`, `protocol_minor`: the version the server announces and speaks
        (others than PROTOCOL_MAJOR, PROTOCOL_MINOR for testing only; below minor 5 no 2.5
        field is sent and omit_fields_from_reply is ignored);
        `data_directory`: where SetupBody.mesh_path is resolved (None: refused);
        `output_root`: where FieldsRequest.write_directory is created (None: refused);
        `maximum_dofs`: the largest body (2 degrees of freedom per node) set up, checked after
        the mesh is decoded and before assembly (0: no limit)."""
        self.protocol = protocol          # the robin_pb2 module
        self.name = name
        self.protocol_major = protocol_major
        self.protocol_minor = protocol_minor
        self.data_directory = data_directory
        self.output_root = output_root
        self.maximum_dofs = maximum_dofs
        self.logger = logger or logging.getLogger("robin-subdomain-py")
        self.state = AWAITING_SETUP
        self.shutdown_requested = False
        self.body = None
        self.run_id = ""                  # run_id of the SetupBody of self.body; "" if none
        self.settings = None

    def server_name(self):
        return SERVER_NAME + (" (%s)" % self.name if self.name else "")

    def handle(self, request_bytes):
        """The serialized reply to one request. Never raises."""
        record = _Record()
        start = record.start
        reply = self.protocol.Envelope()
        try:
            request = self.protocol.Envelope()
            try:
                request.ParseFromString(request_bytes)
            except (DecodeError, RuntimeError, ValueError):
                raise RequestError("MALFORMED_MESSAGE", "the message (%d bytes) is not a "
                                   "serialized robin.protocol.Envelope" % len(request_bytes))
            reply.request_id = request.request_id
            reply.run_id = request.run_id
            content = request.WhichOneof("content")
            record.type = self._type_name(request, content)
            if self.body is not None:
                record.body = self.body.name
            self._check_version(request)
            self._dispatch(request, content, reply, record)
        except RequestError as error:
            self._set_error(reply, error.code, str(error))
        except SingularBodyError as error:
            self._set_error(reply, "SINGULAR_BODY", str(error))
        except InputError as error:
            self._set_error(reply, "BAD_INPUT", str(error))
        except Exception as error:  # noqa: BLE001 - every failure becomes an INTERNAL reply
            self._set_error(reply, "INTERNAL", "internal error: %s" % error)
        return self._finish(reply, record, time.perf_counter() - start)

    def reject(self, reason):
        """The MALFORMED_MESSAGE reply (request_id 0) to a message the transport could not pass
        to handle(), e.g. one of several frames."""
        reply = self.protocol.Envelope()
        self._set_error(reply, "MALFORMED_MESSAGE", reason)
        return self._finish(reply, _Record(), 0.0)

    def _type_name(self, request, content):
        if content is None:
            return "(no content)"
        return request.DESCRIPTOR.fields_by_name[content].message_type.name

    def _set_error(self, reply, code, message):
        reply.error.code = self.protocol.ErrorCode.Value(code)
        reply.error.message = message
        reply.error.state = self.state

    def _finish(self, reply, record, seconds):
        if reply.HasField("error"):
            record.failed = True
            record.outcome = "%s: %s" % (self.protocol.ErrorCode.Name(reply.error.code),
                                         reply.error.message)
        reply.version.major = self.protocol_major
        reply.version.minor = self.protocol_minor
        body = " body '%s'" % record.body if record.body else ""
        self.logger.log(logging.WARNING if record.failed else logging.INFO, "%s%s%s: %s (%.3f ms)",
                        record.type, body, record.iteration, record.outcome, 1e3 * seconds)
        return reply.SerializeToString()

    def _check_version(self, request):
        if not request.HasField("version"):
            raise RequestError("MALFORMED_MESSAGE", "the Envelope carries no version: every "
                               "message must carry the sender's protocol Version")
        major = request.version.major
        if major != self.protocol_major:
            raise RequestError(
                "VERSION_MISMATCH",
                "protocol version mismatch: the request speaks %d.%d, this server %d.%d (the major "
                "versions must be equal); use a matching coordinator or server" %
                (major, request.version.minor, self.protocol_major, self.protocol_minor))

    def _dispatch(self, request, content, reply, record):
        handlers = {"hello": self._on_hello, "setup_body": self._on_setup_body,
                    "assign_contact": self._on_assign_contact,
                    "contact_solve": self._on_contact_solve, "correction": self._on_correction,
                    "neumann_solve": self._on_neumann_solve, "fields": self._on_fields,
                    "end_run": self._on_end_run, "shutdown": self._on_shutdown,
                    "set_load_factor": self._on_set_load_factor}
        if content in handlers:
            return handlers[content](request, reply, record)
        if content is not None:
            raise RequestError("UNSUPPORTED", "%s is a reply, not a request" %
                               self._type_name(request, content))
        if len(request.UnknownFields()) > 0:
            raise RequestError("UNSUPPORTED", "the request type is unknown to this server "
                               "(protocol %d.%d); check HelloReply.capabilities" %
                               (self.protocol_major, self.protocol_minor))
        raise RequestError("MALFORMED_MESSAGE", "the Envelope carries no request (no content)")

    def _require_state(self, minimum, request_type):
        if self.state == AWAITING_SETUP and minimum != AWAITING_SETUP:
            raise RequestError("WRONG_STATE", "%s before SetupBody: send SetupBody first" %
                               request_type)
        if self.state == AWAITING_ASSIGNMENT and minimum == READY:
            raise RequestError("WRONG_STATE", "%s before AssignContact: send AssignContact for "
                               "body '%s' first" % (request_type, self.body.name))

    def _require_same_run(self, request, request_type):
        """WRONG_STATE when the request names another run than the body's (protocol 1.2)."""
        if (self.body is None or not self.run_id or not request.run_id
                or request.run_id == self.run_id):
            return
        raise RequestError("WRONG_STATE", "%s of run '%s': this server's body '%s' now belongs to "
                           "another run (run_id '%s'): another coordinator set it up; this run's "
                           "state is lost" % (request_type, request.run_id, self.body.name,
                                              self.run_id))

    def _acknowledge(self, reply):
        reply.acknowledge.state = self.state

    def _on_hello(self, request, reply, record):
        reply.hello_reply.server_name = self.server_name()
        reply.hello_reply.capabilities.extend(CAPABILITIES)
        reply.hello_reply.state = self.state

    def _on_end_run(self, request, reply, record):
        self._require_same_run(request, "EndRun")
        self.body = None
        self.run_id = ""
        self.state = AWAITING_SETUP
        self._acknowledge(reply)

    def _check_size(self, definition):
        """InputError when the body is above --max-dofs (before any assembly)."""
        dof_count = definition.mesh.dof_count()
        if self.maximum_dofs and dof_count > self.maximum_dofs:
            raise InputError("body '%s': %d degrees of freedom, above this server's limit of %d "
                             "(robin-subdomain-py --max-dofs raises it)" %
                             (definition.name, dof_count, self.maximum_dofs))

    def _on_shutdown(self, request, reply, record):
        self.shutdown_requested = True
        self._acknowledge(reply)

    def _on_setup_body(self, request, reply, record):
        self.body = None                  # a SetupBody starts a new run, whatever its outcome
        self.run_id = ""                  # (and whichever run the body belonged to)
        self.state = AWAITING_SETUP
        record.body = quoted(request.setup_body.body_name, 64)[1:-1]
        if request.setup_body.floating:
            # Since 2.3: a body held by contact alone needs the generalized inverse and the
            # equality-constrained dual (docs/method.md, "Floating bodies"), which this
            # reference server does not implement.
            raise RequestError("UNSUPPORTED", "body '%s' is floating (held by contact alone): "
                               "this server solves only bodies whose supports remove every "
                               "rigid motion; run it on robin-subdomain" % record.body)
        mesh_start = time.perf_counter()
        definition, settings = decode_setup_body(request.setup_body, self.protocol,
                                                 self.data_directory)
        mesh_seconds = time.perf_counter() - mesh_start
        self._check_size(definition)
        body = Body(definition)
        self._describe_interface(body, reply.interface)
        # Since 2.2: the stages (SuperLU orders and factorizes in one call: no "ordering" of
        # its own, "factorization" holds both) and the whole request on this server.
        _add_stage_times(reply.interface.stage_times, (
            ("mesh", mesh_seconds), ("assembly", body.assembly_seconds),
            ("factorization", body.factorization_seconds)))
        reply.interface.request_seconds = time.perf_counter() - record.start
        if self._reports_peak_resident():
            reply.interface.peak_resident_bytes = peak_resident_bytes()
        self.settings = settings
        self.body = body
        self.run_id = request.run_id
        self.state = AWAITING_ASSIGNMENT
        record.outcome = "ok, %d nodes, %d free dofs, %d contact boundary nodes" % (
            body.mesh.node_count(), body.free_dof_count(), body.interface.size())
        if self.run_id:
            record.outcome += ", run " + self.run_id

    def _describe_interface(self, body, description):
        """Fills the InterfaceDescription of `body` (contact_boundaries.ContactBoundaries)."""
        interface = body.interface
        description.body_name = body.name
        description.dimension = body.mesh.dimension
        description.node_ids.extend(int(node) for node in interface.node_ids)
        description.node_tags.extend(int(tag) for tag in interface.node_tags)
        description.coordinates.extend(interface.coordinates.ravel().tolist())
        description.normals.extend(interface.normals.ravel().tolist())
        description.weights.extend(interface.weights.tolist())
        description.fixed.extend(bool(flag) for flag in interface.fixed.ravel())
        for surface in interface.surfaces:
            message = description.surfaces.add()
            message.boundary = surface.name
            message.segment_type = self.protocol.CellType.Value(surface.segment_type.upper())
            message.segments.extend(int(position) for position in surface.segments.ravel())
        description.dof_count = body.free_dof_count()
        description.setup_seconds = body.assembly_seconds + body.factorization_seconds

    def _on_assign_contact(self, request, reply, record):
        self._require_same_run(request, "AssignContact")
        self._require_state(AWAITING_ASSIGNMENT, "AssignContact")
        operator = decode_assign_contact(request.assign_contact, self.body.interface.node_ids,
                                         self.body.mesh.node_tags, self.body.name,
                                         self.body.mesh.dimension)
        self.state = AWAITING_ASSIGNMENT  # until the body accepted the assignment
        start = time.perf_counter()
        self.body.assign_contact(operator)
        interface_seconds = time.perf_counter() - start
        self.state = READY
        self._acknowledge(reply)
        _add_stage_times(reply.acknowledge.stage_times, (("interface operator", interface_seconds),))
        if self._reports_peak_resident():
            reply.acknowledge.peak_resident_bytes = peak_resident_bytes()
        record.outcome = "ok, %d constraints, %d entries" % (operator.row_count,
                                                             len(operator.values))

    def _require_finite(self, result, request_type, record):
        """SOLVER_FAILURE instead of a reply `result` that holds a NaN or infinite number."""
        found = first_non_finite(result, result.DESCRIPTOR.name)
        if found is None:
            return
        raise RequestError("SOLVER_FAILURE", "body '%s': %s%s: the reply would carry the "
                           "non-finite number %s = %r, which is never sent: the solver failed "
                           "(check the body's material, loads and the request's values)" %
                           (self.body.name, request_type, record.iteration, found[0], found[1]))

    def _on_contact_solve(self, request, reply, record):
        message = request.contact_solve
        record.iteration = " iteration %d" % message.iteration
        self._require_same_run(request, "ContactSolveRequest")
        self._require_state(READY, "ContactSolveRequest")
        interface = self.body.contact
        obstacle = _checked_vector(message.obstacle, interface.size(),
                                   "ContactSolveRequest.obstacle", self.body.name)
        result = interface.solve_contact(obstacle, self.settings.qp_tolerance,
                                         self.settings.qp_max_iterations)
        out = reply.contact_result
        out.normal_trace.extend(result["normal_trace"].tolist())
        out.contact_force.extend(result["contact_force"].tolist())
        out.active.extend(bool(flag) for flag in result["active"])
        out.status = self.protocol.SolveStatus.Value(result["status"])
        out.qp_iterations = result["iterations"]
        out.projected_gradient_norm = result["projected_gradient_norm"]
        out.penetration = result["penetration"]
        out.complementarity = result["complementarity"]
        out.compute_seconds = result["seconds"]
        out.message = result["message"]
        self._require_finite(out, "ContactSolveRequest", record)
        record.outcome = "%s, %d QP iterations" % (result["status"], result["iterations"])
        if result["message"]:
            record.outcome += " (%s)" % result["message"]

    def _on_correction(self, request, reply, record):
        start = time.perf_counter()
        message = request.correction
        record.iteration = " iteration %d" % message.iteration
        self._require_same_run(request, "CorrectionRequest")
        self._require_state(READY, "CorrectionRequest")
        interface = self.body.contact
        force = _checked_vector(message.interface_force, interface.size(),
                                "CorrectionRequest.interface_force", self.body.name)
        reply.correction_result.normal_trace.extend(interface.solve_correction(force).tolist())
        reply.correction_result.compute_seconds = time.perf_counter() - start
        self._require_finite(reply.correction_result, "CorrectionRequest", record)

    def _on_neumann_solve(self, request, reply, record):
        """Since protocol 1.1: K u = f - B' lambda for the given lambda; replies u_N = B u."""
        start = time.perf_counter()
        message = request.neumann_solve
        record.iteration = " iteration %d" % message.iteration
        self._require_same_run(request, "NeumannSolveRequest")
        self._require_state(READY, "NeumannSolveRequest")
        interface = self.body.contact
        force = _checked_vector(message.contact_force, interface.size(),
                                "NeumannSolveRequest.contact_force", self.body.name)
        trace = interface.solve_neumann(force)
        reply.neumann_result.normal_trace.extend(trace.tolist())
        reply.neumann_result.compute_seconds = time.perf_counter() - start
        self._require_finite(reply.neumann_result, "NeumannSolveRequest", record)
        record.outcome = "ok, max |lambda| %.3e, max |u_N| %.3e" % (
            np.max(np.abs(force), initial=0.0), np.max(np.abs(trace), initial=0.0))

    def _on_set_load_factor(self, request, reply, record):
        """Since protocol 2.1: scales the body's loads and prescribed displacements; the factor
        of K, B and F are kept and the state does not change."""
        start = time.perf_counter()
        factor = request.set_load_factor.factor
        record.iteration = " factor %r" % factor
        self._require_same_run(request, "SetLoadFactor")
        self._require_state(AWAITING_ASSIGNMENT, "SetLoadFactor")
        if not np.isfinite(factor) or abs(factor) > MAXIMUM_LOAD_FACTOR:
            raise RequestError("BAD_INPUT", "SetLoadFactor.factor = %r for body '%s' is not a "
                               "finite number of magnitude at most 1e6" % (factor, self.body.name))
        self.body.set_load_factor(factor)
        reply.load_factor_set.factor = self.body.load_factor
        reply.load_factor_set.state = self.state
        reply.load_factor_set.compute_seconds = time.perf_counter() - start

    def _reports_peak_resident(self):
        """Whether replies carry peak_resident_bytes (protocol 2.5)."""
        return self.protocol_minor >= 5

    def _omits_fields(self, message):
        """Whether the FieldsReply leaves out the mesh and the fields (2.5,
        omit_fields_from_reply; ignored below 5); INVALID_ARGUMENT without write_directory."""
        if self.protocol_minor < 5 or not message.omit_fields_from_reply:
            return False
        if not message.write_directory:
            raise RequestError("INVALID_ARGUMENT", "body '%s': FieldsRequest."
                               "omit_fields_from_reply is set without write_directory: the "
                               "fields would go nowhere" % self.body.name)
        return True

    def _on_fields(self, request, reply, record):
        start = time.perf_counter()
        message = request.fields
        self._require_same_run(request, "FieldsRequest")
        self._require_state(READY, "FieldsRequest")
        omit_fields = self._omits_fields(message)
        force = _checked_vector(message.contact_force, self.body.contact.size(),
                                "FieldsRequest.contact_force", self.body.name)
        if message.write_directory:
            self._output_refusal(lambda: check_output_directory(self.output_root,
                                                                message.write_directory),
                                 message.write_directory)
        fields = body_fields(self.body, force)
        self._fill_fields_reply(fields, reply.fields_reply)
        self._require_finite(reply.fields_reply, "FieldsRequest", record)
        if message.write_directory:
            text = vtu_bytes(self.body.mesh, fields)
            path = self._output_refusal(
                lambda: write_under_root(self.output_root, message.write_directory,
                                         self.body.name + ".vtu", text),
                message.write_directory)
            reply.fields_reply.written_file = path
        if omit_fields:   # the file holds them, written exactly as without the flag
            for name in OMITTED_FIELDS:
                reply.fields_reply.ClearField(name)
        _add_stage_times(reply.fields_reply.stage_times, (("fields", time.perf_counter() - start),))
        if self._reports_peak_resident():
            reply.fields_reply.peak_resident_bytes = peak_resident_bytes()

    def _output_refusal(self, action, write_directory):
        """action(), its PathRefused or OSError an INVALID_ARGUMENT naming the body and the
        field."""
        try:
            return action()
        except PathRefused as refusal:
            problem = str(refusal)
        except OSError as error:
            problem = "cannot be written: %s" % (error.strerror or error)
        raise RequestError("INVALID_ARGUMENT", "FieldsRequest.write_directory %s of body '%s' %s"
                           % (quoted(write_directory), self.body.name, problem))

    def _fill_fields_reply(self, fields, out):
        """The mesh and the BodyFields of the body in a FieldsReply."""
        mesh = self.body.mesh
        if mesh.dimension == 3:
            out.dimension = 3   # since 2.4; absent (2) for a plane body
        out.node_coordinates.extend(mesh.nodes.ravel().tolist())
        out.node_tags.extend(int(tag) for tag in mesh.node_tags)
        out.cell_offsets.append(0)
        for block in mesh.blocks:
            out.cell_types.append(VTK_CELL_TYPE[block.type])
            out.connectivity.extend(int(node) for node in block.connectivity.ravel())
            out.cell_offsets.append(len(out.connectivity))
        for name in sorted(mesh.boundaries):  # since 2.1: the named boundaries, for the output
            boundary = out.boundaries.add()
            boundary.name = name
            group = mesh.boundaries[name]
            boundary.segments.type = self.protocol.CellType.Value(group.type.upper())
            boundary.segments.connectivity.extend(int(node) for node in group.connectivity.ravel())
        for target, source in ((out.point_fields, fields.point_fields),
                               (out.cell_fields, fields.cell_fields)):
            for name, components, values in source:
                field = target.add()
                field.name = name
                field.components = components
                field.values.extend(np.ravel(values).tolist())
        out.reaction_resultant.extend(fields.reaction_resultant.tolist())
        out.applied_force.extend(fields.applied_force.tolist())
