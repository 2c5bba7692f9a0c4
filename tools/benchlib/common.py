"""Helpers the other modules share: the repository root, the log on stderr,
JSON files and file stamps."""

import json
import os
import sys

# tools/benchlib/common.py: three folders up is the repository.
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def load_json(path):
    with open(path) as f:
        return json.load(f)


def write_json_if_changed(path, data):
    text = json.dumps(data, indent=2, sort_keys=True) + "\n"
    if os.path.exists(path) and open(path).read() == text:
        return
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def file_stamp(path):
    st = os.stat(path)
    return f"{os.path.abspath(path)}:{st.st_mtime_ns}:{st.st_size}"


def replace_block(md_path, begin, end, block, heading):
    """Writes `block` (which starts with `begin` and ends with `end`) into
    md_path in place of the part between those markers, or appends it under a
    new `## heading` where the markers are not there yet. Text outside the
    markers is hand-written and kept as it is."""
    text = open(md_path).read() if os.path.exists(md_path) else ""
    if begin in text and end in text:
        text = text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    else:
        text = text.rstrip("\n") + f"\n\n## {heading}\n\n" + block + "\n"
    tmp = md_path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, md_path)
