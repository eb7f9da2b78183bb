#!/usr/bin/env python3
"""The namespace rule (docs/architecture.md, "Namespaces"), checked on every source file.

The layers whose types every other layer names (util, registry, geometry, camera,
instrument, mocap) are in `arco::`; the test support folder testing/ in `arco::testing`;
export/ in `arco::exporter` (`export` is a C++ keyword); every other layer in
`arco::<folder>`. Inside a layer, nested namespaces of its own are free (`::testing`,
`::internal`; for the `arco::` layers only these two). A block that only forward-declares
another layer's types (`namespace arco { struct CaptureManifest; }`) is not a file in the
wrong namespace. Prints one line per violation and exits 1 when there is any.

usage: namespace_rule_test.py SOURCE_DIR
"""
import pathlib
import re
import sys

PLAIN = {"util", "registry", "geometry", "camera", "instrument", "mocap"}
SPECIAL = {"testing": "arco::testing", "export": "arco::exporter"}
OPEN = re.compile(r"^namespace (arco(?:::\w+)*) \{\s*(?://.*)?$")
FORWARD = re.compile(r"^\s*(?:(?:class|struct|enum class|enum)\s+\w+(?:\s*:\s*[\w:]+)?;|//.*|)\s*$")


def expected(layer):
    if layer in PLAIN:
        return "arco"
    return SPECIAL.get(layer, "arco::" + layer)


def allowed(layer, name):
    want = expected(layer)
    if want == "arco":
        return name in ("arco", "arco::testing", "arco::internal")
    return name == want or name.startswith(want + "::")


def forward_only(lines, start):
    """True when the block opened at lines[start] holds only forward declarations."""
    for line in lines[start + 1:]:
        if line.startswith("}"):
            return True
        if not FORWARD.match(line):
            return False
    return False


def main():
    root = pathlib.Path(sys.argv[1]) / "src" / "arco"
    bad = []
    checked = 0
    for layer_dir in sorted(p for p in root.iterdir() if p.is_dir()):
        layer = layer_dir.name
        for path in sorted(layer_dir.rglob("*")):
            if path.suffix not in (".h", ".cc"):
                continue
            checked += 1
            lines = path.read_text(encoding="utf-8").splitlines()
            for i, line in enumerate(lines):
                m = OPEN.match(line)
                if not m or allowed(layer, m.group(1)) or forward_only(lines, i):
                    continue
                bad.append(f"{path.relative_to(root.parent.parent)}:{i + 1}: namespace "
                           f"{m.group(1)}; {layer}/'s files are in {expected(layer)} "
                           "(docs/architecture.md, \"Namespaces\")")
    for line in bad:
        print(line)
    print(f"{checked} files checked, {len(bad)} in another layer's namespace")
    return 1 if bad or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
