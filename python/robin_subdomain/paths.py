"""The files a request may name, confined to the directories the server's operator chose at start.

resolve_data_file     SetupBody.mesh_path: a relative path under --data-directory, its real path
                      (symbolic links followed) inside the real path of that directory.
write_under_root      FieldsRequest.write_directory: a relative path under --output-root, its
                      missing directories created one by one without following a symbolic link,
                      the file written to a temporary file in the directory and renamed over the
                      target (a symbolic link at the target is replaced, never followed).
Both refuse with PathRefused, whose message says why and what to send instead; the caller adds
the body and the field.
"""

import os
import secrets
import stat


class PathRefused(Exception):
    """A path a request may not use: outside the operator's directory, or no directory given."""


def _is_inside(path, root):
    """True when the absolute, normalised `path` is `root` or lies below it."""
    return os.path.commonpath([path, root]) == root


def _check_relative(relative, what):
    if "\0" in relative:
        raise PathRefused("contains a NUL character")
    if os.path.isabs(relative):
        raise PathRefused("is an absolute path: give a path relative to the %s" % what)


def resolve_data_file(data_directory, relative):
    """The real path of the file `relative` names under `data_directory` (None: the server has
    no data directory). PathRefused when there is no data directory, the path is absolute, or
    its real path leaves the real path of the data directory (through '..' or a symbolic link).
    Nothing is opened: the file may not exist (the reader reports that)."""
    if data_directory is None:
        raise PathRefused("is refused: the server was started without --data-directory, so it "
                          "reads no mesh file; send the mesh as SetupBody.mesh (MeshData), or "
                          "start the server with --data-directory DIR")
    _check_relative(relative, "server's data directory")
    root = os.path.realpath(data_directory)
    real = os.path.realpath(os.path.join(root, relative))
    if not _is_inside(real, root):
        raise PathRefused("leaves the server's data directory (through '..' or a symbolic link): "
                          "give a path to a file under it")
    return real


def _directory_parts(relative):
    """The components of a relative directory path; '..' is refused, '' and '.' dropped."""
    _check_relative(relative, "server's output root")
    parts = [part for part in relative.split(os.sep) if part not in ("", ".")]
    if ".." in parts:
        raise PathRefused("contains '..': give a directory below the server's output root")
    return parts


def _enter(parent, part):
    """The descriptor of directory `part` of the open directory `parent`, created if missing;
    a symbolic link there is refused, never followed (O_NOFOLLOW also against a link that
    appears between the check and the opening)."""
    try:
        os.mkdir(part, 0o777, dir_fd=parent)
    except FileExistsError:
        pass
    mode = os.stat(part, dir_fd=parent, follow_symlinks=False).st_mode
    if stat.S_ISLNK(mode):
        raise PathRefused("goes through the symbolic link '%s': give a directory below the "
                          "server's output root without symbolic links" % part)
    if not stat.S_ISDIR(mode):
        raise PathRefused("names '%s', which is not a directory" % part)
    return os.open(part, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW, dir_fd=parent)


def _replace_file(directory, file_name, text):
    """Writes `text` to a new temporary file in the open directory, then renames it to
    `file_name` (replacing a file or a symbolic link there, never writing through it)."""
    temporary = ".%s.%s.tmp" % (file_name, secrets.token_hex(8))
    descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644,
                         dir_fd=directory)
    try:
        with os.fdopen(descriptor, "wb" if isinstance(text, bytes) else "w") as stream:
            stream.write(text)
        os.replace(temporary, file_name, src_dir_fd=directory, dst_dir_fd=directory)
    except BaseException:
        try:
            os.unlink(temporary, dir_fd=directory)
        except OSError:
            pass
        raise


def check_output_directory(output_root, relative_directory):
    """The components of `relative_directory` when it may be written under `output_root`
    (None: the server has no output root): PathRefused without an output root, for an absolute
    path or '..'. Symbolic links are found by write_under_root."""
    if output_root is None:
        raise PathRefused("is refused: the server was started without --output-root, so it "
                          "writes no file; leave write_directory empty, or start the server "
                          "with --output-root DIR")
    return _directory_parts(relative_directory)


def write_under_root(output_root, relative_directory, file_name, text):
    """Writes `text` to <output_root>/<relative_directory>/<file_name> and returns that path
    (under the real path of the root). PathRefused as check_output_directory, and for a
    symbolic link or a non-directory on the way; OSError when the file system refuses."""
    parts = check_output_directory(output_root, relative_directory)
    root = os.path.realpath(output_root)
    directory = os.open(root, os.O_RDONLY | os.O_DIRECTORY)
    try:
        for part in parts:
            child = _enter(directory, part)
            os.close(directory)
            directory = child
        path = os.path.join(root, *parts)
        if not _is_inside(os.path.realpath(path), root):
            raise PathRefused("leaves the server's output root")
        _replace_file(directory, file_name, text)
    finally:
        os.close(directory)
    return os.path.join(path, file_name)
