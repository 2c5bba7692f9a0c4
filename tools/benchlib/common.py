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
