"""The process's peak resident set size, for the replies of the long requests (protocol 2.5:
peak_resident_bytes of InterfaceDescription, Acknowledge and FieldsReply), as robin-subdomain
reports it (subdomain/server/resident_memory.cpp)."""

import sys

STATUS_FILE = "/proc/self/status"


def high_water_mark_bytes(status_file=STATUS_FILE):
    """VmHWM of a /proc/PID/status file in bytes; None when the file cannot be read or has no
    VmHWM line in kB."""
    try:
        with open(status_file, encoding="ascii", errors="replace") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    fields = line[len("VmHWM:"):].split()
                    if len(fields) == 2 and fields[1] == "kB" and fields[0].isdigit():
                        return int(fields[0]) * 1024
                    return None
    except OSError:
        return None
    return None


def maximum_resident_bytes_from_usage():
    """getrusage(RUSAGE_SELF).ru_maxrss in bytes on Linux (where it counts kibibytes); None
    elsewhere or when the resource module is missing."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        import resource
    except ImportError:
        return None
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def peak_resident_bytes(status_file=STATUS_FILE):
    """The peak resident set size of this process so far, in bytes: VmHWM of `status_file`,
    else ru_maxrss (Linux), else 0 (not reported)."""
    for measured in (high_water_mark_bytes(status_file), maximum_resident_bytes_from_usage()):
        if measured:
            return measured
    return 0
