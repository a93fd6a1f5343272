"""robin-subdomain-py: serves one elastic body of a robin-contact run over ZeroMQ
(proto/robin.proto, protocol 2.5), with the command line of the C++ robin-subdomain.

Files: the server reads a mesh file only for SetupBody.mesh_path, and only under the directory
given by --data-directory DIR (without it every mesh_path is refused); it writes result files
only for FieldsRequest.write_directory, and only under --output-root DIR (without it every
write_directory is refused). Both must be existing directories (else exit status 2).

Prints exactly one line on stdout, "listening on ENDPOINT", once bound (wildcards and ephemeral
ports resolved through ZMQ_LAST_ENDPOINT); logs go to stderr. The REP socket has linger 0,
maxmsgsize (a larger message is dropped by libzmq and its sender disconnected) and a send
timeout after which the socket is re-created on the same endpoint. A message of several frames
gets a MALFORMED_MESSAGE reply.
Exit codes: 0 after Shutdown, SIGINT or SIGTERM; 1 when the endpoint cannot be bound or the
transport fails; 2 for a bad command line, including robin-subdomain's CurveZMQ options
(--curve-secret-key, --curve-allow): this server speaks plain ZeroMQ only and says so.
"""

import argparse
import errno
import logging
import os
import signal
import sys
import time

from .proto_module import load_protocol
from .protocol import DEFAULT_MAXIMUM_DOFS, PROTOCOL_MAJOR, PROTOCOL_MINOR, SubdomainProtocol

LOG_LEVELS = {"trace": 5, "debug": logging.DEBUG, "info": logging.INFO, "warn": logging.WARNING,
              "error": logging.ERROR, "critical": logging.CRITICAL, "off": logging.CRITICAL + 10}
POLL_MILLISECONDS = 200


class BindError(Exception):
    pass


CURVE_REFUSAL = (
    "%s is not supported: robin-subdomain-py, the Python reference server, speaks plain ZeroMQ "
    "only (no CurveZMQ encryption or authentication). Bind it to loopback "
    "(--listen tcp://127.0.0.1:PORT) and reach it through an SSH tunnel "
    "(ssh -L PORT:127.0.0.1:PORT HOST), or run it only on a network you trust; see "
    "docs/security.md, 'What is not protected'. For CurveZMQ, use robin-subdomain.")


def product_version():
    """The product version: the file VERSION at the top of the repository (the one place it is
    kept, also read by CMake), or "unknown" when the server runs outside the repository."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir,
                        "VERSION")
    try:
        with open(path, encoding="utf-8") as file:
            return file.readline().strip() or "unknown"
    except OSError:
        return "unknown"


def curve_option(arguments):
    """The first argument that is one of robin-subdomain's CurveZMQ options (--curve-secret-key,
    --curve-allow, with "=VALUE" or abbreviated as argparse allows: any word starting with
    "--curve"), or None."""
    for word in arguments:
        if word == "--":
            break
        if word.startswith("--curve"):
            return word.split("=", 1)[0]
    return None


def parse_arguments(arguments):
    """The options of `arguments`; exits with status 2 (argparse's message) for a bad command
    line, and with status 2 and CURVE_REFUSAL for a CurveZMQ option."""
    parser = argparse.ArgumentParser(
        prog="robin-subdomain-py",
        description="robin-subdomain-py: serves one elastic body of a robin-contact run over "
                    "ZeroMQ (Python reference implementation)")
    parser.add_argument("--listen", required=True,
                        help="ZeroMQ endpoint to bind: tcp://HOST:PORT, tcp://*:PORT, "
                             "tcp://127.0.0.1:* (ephemeral port) or ipc://PATH")
    parser.add_argument("--log-level", default="info", choices=list(LOG_LEVELS),
                        help="trace, debug, info, warn, error or off (default info)")
    parser.add_argument("--max-message-size", type=int, default=1 << 30,
                        help="largest accepted request in bytes; libzmq drops a larger message "
                             "and disconnects its sender, who gets no reply")
    parser.add_argument("--name", default="", help="label for the logs and HelloReply")
    parser.add_argument("--data-directory", metavar="DIR",
                        help="directory of the mesh files SetupBody.mesh_path may name "
                             "(relative paths that stay inside it); without it every mesh_path "
                             "is refused")
    parser.add_argument("--output-root", metavar="DIR",
                        help="directory under which FieldsRequest.write_directory is created "
                             "(relative paths, no symbolic links); without it every "
                             "write_directory is refused")
    parser.add_argument("--max-dofs", type=int, default=DEFAULT_MAXIMUM_DOFS, metavar="N",
                        help="largest body set up, in degrees of freedom (2 per node), checked "
                             "before assembly (default %d; 0: no limit). The factor's memory is "
                             "bounded through it only: SciPy's SuperLU has no symbolic "
                             "analysis to estimate it beforehand" % DEFAULT_MAXIMUM_DOFS)
    parser.add_argument("--version", action="version",
                        version="robin-subdomain-py %s (protocol %d.%d)" %
                        (product_version(), PROTOCOL_MAJOR, PROTOCOL_MINOR),
                        help="print the product and protocol versions and exit")
    parser.add_argument("--send-timeout-ms", type=int, default=10000, help=argparse.SUPPRESS)
    # Testing only: announce and accept another protocol major version.
    parser.add_argument("--protocol-major", type=int, default=PROTOCOL_MAJOR,
                        help=argparse.SUPPRESS)
    # Testing only: announce another protocol minor version and speak it (below 5: no
    # peak_resident_bytes, omit_fields_from_reply ignored), as robin-subdomain --protocol-minor.
    parser.add_argument("--protocol-minor", type=int, default=PROTOCOL_MINOR,
                        help=argparse.SUPPRESS)
    curve = curve_option(arguments)
    if curve is not None:
        parser.exit(2, "%s: error: %s\n" % (parser.prog, CURVE_REFUSAL % curve))
    options = parser.parse_args(arguments)
    if options.max_message_size <= 0:
        parser.error("--max-message-size must be a positive number")
    if options.protocol_minor < 0:
        parser.error("--protocol-minor must be 0 or a positive number")
    if options.max_dofs < 0:
        parser.error("--max-dofs must be 0 (no limit) or a positive number")
    for option, value in (("--data-directory", options.data_directory),
                          ("--output-root", options.output_root)):
        if value is not None and not os.path.isdir(value):
            parser.error("%s '%s' is not an existing directory" % (option, value))
    return options


def make_logger(level, name):
    for spelled, number in LOG_LEVELS.items():
        if spelled != "off":
            logging.addLevelName(number, "warning" if spelled == "warn" else spelled)
    logger = logging.getLogger("robin-subdomain-py")
    handler = logging.StreamHandler(sys.stderr)
    label = "robin-subdomain-py" + (" " + name if name else "")
    handler.setFormatter(logging.Formatter(
        "[%(asctime)s.%(msecs)03d] [" + label + "] [%(levelname)s] %(message)s",
        "%Y-%m-%d %H:%M:%S"))
    logger.handlers[:] = [handler]
    logger.setLevel(LOG_LEVELS[level])
    logger.propagate = False
    return logger


class ReplySocket:
    """The REP socket, re-created on the same (resolved) endpoint after a failed send."""

    def __init__(self, zmq, context, options):
        self.zmq = zmq
        self.context = context
        self.options = options
        try:
            self.socket = self._open(options.listen)
        except zmq.ZMQError as error:
            raise BindError("cannot listen on '%s': %s" % (options.listen, error))
        self.endpoint = self.socket.getsockopt_string(zmq.LAST_ENDPOINT)

    def _open(self, endpoint):
        zmq = self.zmq
        socket = self.context.socket(zmq.REP)
        socket.setsockopt(zmq.LINGER, 0)
        socket.setsockopt(zmq.MAXMSGSIZE, self.options.max_message_size)
        socket.setsockopt(zmq.SNDTIMEO, self.options.send_timeout_ms)
        try:
            socket.bind(endpoint)
        except self.zmq.ZMQError:
            socket.close()
            raise
        return socket

    def reopen(self):
        """Closes the socket (dropping a pending reply) and binds a new one to the endpoint;
        retries for about a second while the old listener is being released."""
        self.socket.close()
        for attempt in range(21):
            try:
                self.socket = self._open(self.endpoint)
                return
            except self.zmq.ZMQError as error:
                if error.errno != errno.EADDRINUSE or attempt == 20:
                    raise BindError("cannot listen again on '%s': %s" % (self.endpoint, error))
                time.sleep(0.05)


def serve(protocol_handler, options, stop, logger):
    """Serves until a Shutdown was answered or stop() is true; returns the reason."""
    import zmq
    context = zmq.Context(1)
    socket = ReplySocket(zmq, context, options)
    try:
        logger.info("%s listening on %s (max message size %d bytes)",
                    protocol_handler.server_name(), socket.endpoint, options.max_message_size)
        sys.stdout.write("listening on %s\n" % socket.endpoint)   # the launcher reads this line
        sys.stdout.flush()
        # Nothing else goes to stdout: stray output joins the logs on stderr.
        os.dup2(sys.stderr.fileno(), sys.stdout.fileno())
        sys.stdout = sys.stderr
        poller = zmq.Poller()
        while not stop():
            poller.register(socket.socket, zmq.POLLIN)
            ready = dict(poller.poll(POLL_MILLISECONDS))
            poller.unregister(socket.socket)
            if socket.socket not in ready:
                continue
            frames = socket.socket.recv_multipart(copy=True)
            if not frames:
                continue
            if len(frames) == 1:
                reply = protocol_handler.handle(frames[0])
            else:
                reply = protocol_handler.reject(
                    "the message has %d frames, expected one (a serialized Envelope)" % len(frames))
            try:
                socket.socket.send(reply)
            except zmq.Again:
                logger.warning("the reply could not be sent within %d ms (client gone?); "
                               "re-creating the socket on %s", options.send_timeout_ms,
                               socket.endpoint)
                socket.reopen()
            if protocol_handler.shutdown_requested:
                return "Shutdown request"
        return "stop requested"
    finally:
        socket.socket.close(linger=0)
        context.term()


def main(arguments=None):
    options = parse_arguments(sys.argv[1:] if arguments is None else arguments)
    logger = make_logger(options.log_level, options.name)
    stop_requested = []

    def request_stop(signal_number, frame):
        stop_requested.append(signal_number)

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    try:
        protocol_module = load_protocol()
        handler = SubdomainProtocol(protocol_module, options.name, options.protocol_major, logger,
                                    data_directory=options.data_directory,
                                    output_root=options.output_root,
                                    maximum_dofs=options.max_dofs,
                                    protocol_minor=options.protocol_minor)
        reason = serve(handler, options, lambda: bool(stop_requested), logger)
        logger.info("stopped: %s", reason)
        return 0
    except BindError as error:
        logger.error("%s", error)
    except Exception as error:  # noqa: BLE001 - a transport failure ends the process with 1
        logger.critical("transport failure: %s", error)
    return 1
