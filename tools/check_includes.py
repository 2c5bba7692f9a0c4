#!/usr/bin/python3
"""Checks every #include "..." under host/ and shaders/ against the folder
rules in docs/architecture.md (the rules are read from there). A "never
reaches" rule may also name a system header or a prefix of one
(`<vulkan/`): no header the folder reaches may include it.

usage: tools/check_includes.py [REPO_ROOT]   exit 0: all hold; 1: violations
(one line each: FILE:LINE: FOLDER may not include TARGET); 2: bad rules.
"""
import os
import re
import sys

SOURCE_EXT = (".h", ".hpp", ".cpp", ".glsl", ".comp")
RULE = re.compile(r"^- `([^`]+)` (may include|never reaches) (.*)$")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
SYSTEM_INCLUDE = re.compile(r"^\s*#\s*include\s+(<[^>]+>)")


def read_rules(doc):
    allowed, never = {}, []
    with open(doc, encoding="utf-8") as f:
        for line in f:
            m = RULE.match(line.rstrip())
            if not m:
                continue
            folder, kind, rest = m.groups()
            targets = re.findall(r"`([^`]+)`", rest)
            if kind == "may include":
                if not targets and rest.strip() != "(nothing)":
                    raise ValueError("rule without folders: " + line.strip())
                allowed.setdefault(folder, set()).update(targets)
            else:
                never += [(folder, t) for t in targets]
    return allowed, never


def sources(root):
    for top in ("host", "shaders"):
        for d, _, files in os.walk(os.path.join(root, top)):
            for name in sorted(files):
                if name.endswith(SOURCE_EXT):
                    yield os.path.relpath(os.path.join(d, name), root)


def resolve(root, includer, name):
    """The repository path an include names, or None (a system/third-party header)."""
    here = os.path.dirname(includer)
    bases = ([here] if includer.startswith("shaders") else []) + ["host", "shaders"]
    for base in bases:
        path = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(os.path.join(root, path)):
            return path
    return None


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    try:
        allowed, never = read_rules(os.path.join(root, "docs", "architecture.md"))
    except (OSError, ValueError) as e:
        print("check_includes: " + str(e))
        return 2
    if not allowed:
        print("check_includes: no rules found in docs/architecture.md")
        return 2
    edges = {}  # file -> [(line, included file)]
    system = {}  # file -> [(line, <system header>)]
    for src in sources(root):
        with open(os.path.join(root, src), encoding="utf-8", errors="replace") as f:
            for n, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                target = m and resolve(root, src, m.group(1))
                if target:
                    edges.setdefault(src, []).append((n, target))
                m = SYSTEM_INCLUDE.match(line)
                if m:  # a leaf: only "never reaches" rules look at it
                    system.setdefault(src, []).append((n, m.group(1)))
    bad = []
    for src, incs in sorted(edges.items()):
        folder = os.path.dirname(src)
        if folder not in allowed:
            bad.append(f"{src}: folder {folder} has no rule in docs/architecture.md")
            continue
        for n, target in incs:
            to = os.path.dirname(target)
            if to != folder and to not in allowed[folder]:
                bad.append(f"{src}:{n}: {folder} may not include {target}")
    for folder, forbidden in never:
        for src in sorted(s for s in edges if os.path.dirname(s) == folder):
            seen, stack = {src: [src]}, [src]
            while stack:
                f = stack.pop()
                for _, t in edges.get(f, []):
                    if t not in seen:
                        seen[t] = seen[f] + [t]
                        stack.append(t)
            if forbidden.startswith("<"):
                hits = [c + [h] for t, c in seen.items() for _, h in system.get(t, []) if h.startswith(forbidden)]
            else:
                hits = [c for t, c in seen.items() if t == forbidden or t.startswith(forbidden + "/")]
            if hits:
                chain = min(hits, key=lambda c: (len(c), c))
                bad.append(f"{src}: {folder} never reaches {forbidden}, but " + " -> ".join(chain))
    for b in bad:
        print(b)
    if bad:
        print(f"check_includes: {len(bad)} include(s) break the rules in docs/architecture.md")
        return 1
    print(f"check_includes: {sum(len(v) for v in edges.values())} includes in {len(edges)} files follow docs/architecture.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
