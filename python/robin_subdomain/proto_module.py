"""The Python protobuf module of proto/robin.proto, generated on first use.

robin_pb2.py is not committed: load_protocol() runs `protoc --python_out` on robin.proto into a
cache directory named after the SHA-256 of the .proto text (so an edited .proto gets a fresh
module) and imports it from there. The Debian protoc and python3-protobuf runtime have the same
version (3.21), which the generated code requires.

Where robin.proto is found: the ROBIN_PROTO environment variable, else ../../proto/robin.proto
relative to this package (the repository layout). Where the module is cached:
$ROBIN_PROTO_CACHE, else $XDG_CACHE_HOME/robin-subdomain-py (~/.cache/...), else the system's
temporary directory; the first that is writable.
"""

import hashlib
import importlib.util
import os
import pathlib
import shutil
import subprocess
import tempfile

_loaded = None


def default_proto_path():
    """The robin.proto this package belongs to."""
    configured = os.environ.get("ROBIN_PROTO")
    if configured:
        return pathlib.Path(configured)
    return pathlib.Path(__file__).resolve().parent.parent.parent / "proto" / "robin.proto"


def _cache_roots():
    roots = []
    if os.environ.get("ROBIN_PROTO_CACHE"):
        roots.append(pathlib.Path(os.environ["ROBIN_PROTO_CACHE"]))
    cache_home = os.environ.get("XDG_CACHE_HOME") or os.path.join(
        os.path.expanduser("~"), ".cache")
    roots.append(pathlib.Path(cache_home) / "robin-subdomain-py")
    roots.append(pathlib.Path(tempfile.gettempdir()) / ("robin-subdomain-py-%d" % os.getuid()))
    return roots


def _generate(proto_path, directory):
    """Runs protoc into a fresh directory next to `directory`, then renames it into place
    (atomic, so concurrent servers never import a half-written module)."""
    directory.parent.mkdir(parents=True, exist_ok=True)
    staging = pathlib.Path(tempfile.mkdtemp(prefix=".staging-", dir=directory.parent))
    try:
        shutil.copyfile(proto_path, staging / "robin.proto")
        completed = subprocess.run(
            ["protoc", "--proto_path=" + str(staging), "--python_out=" + str(staging),
             str(staging / "robin.proto")], capture_output=True, text=True, check=False)
        if completed.returncode != 0:
            raise RuntimeError("protoc failed on %s: %s" % (proto_path, completed.stderr.strip()))
        try:
            staging.rename(directory)
        except OSError:
            if not (directory / "robin_pb2.py").is_file():
                raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _module_directory(proto_path):
    digest = hashlib.sha256(proto_path.read_bytes()).hexdigest()[:20]
    problems = []
    for root in _cache_roots():
        directory = root / digest
        if (directory / "robin_pb2.py").is_file():
            return directory
        try:
            _generate(proto_path, directory)
            return directory
        except OSError as error:
            problems.append("%s: %s" % (root, error))
    raise RuntimeError("cannot generate robin_pb2.py from %s in any cache directory (%s)" %
                       (proto_path, "; ".join(problems)))


def load_protocol(proto_path=None):
    """The generated robin_pb2 module (loaded once per process)."""
    global _loaded
    if _loaded is not None:
        return _loaded
    proto_path = pathlib.Path(proto_path) if proto_path else default_proto_path()
    if not proto_path.is_file():
        raise RuntimeError("robin.proto not found at %s (set ROBIN_PROTO)" % proto_path)
    module_path = _module_directory(proto_path) / "robin_pb2.py"
    specification = importlib.util.spec_from_file_location("robin_pb2", module_path)
    module = importlib.util.module_from_spec(specification)
    specification.loader.exec_module(module)
    _loaded = module
    return module
