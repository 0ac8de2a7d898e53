#!/usr/bin/env python3
"""Makes the generated parts of docs/architecture.md, as the man page is made from `--help`:

- the picture of the layers (the libraries in CMakeLists.txt and whom each links publicly) and
  of the folders (each folder's README.md: its first sentence);
- the table of every file and its concept, folder by folder: the first sentence of each file's
  own top comment, under its folder's README paragraph.

Each sits between `<!-- generated: NAME -->` and `<!-- end generated: NAME -->`; the text around
them is written by hand. A folder of code without a README.md, or a file without a top comment,
is an error.

Usage: scripts/architecture-map.py [ROOT] [--check]
  (no flag) rewrite the generated parts of ROOT/docs/architecture.md
  --check   exit 1, saying what differs, when the doc is not what would be written (ctest
            Architecture.map, in `make test`)
"""
import difflib
import pathlib
import re
import sys

# The trees the map covers, in the order it shows them; within each, every folder holding code.
TREES = ["include/proxseg", "src", "apps", "python/src", "python/proxseg", "python/tests", "bench",
         "tests", "fuzz", "examples", "scripts", "cmake"]
CODE = (".cpp", ".hpp", ".hpp.in", ".py", ".sh", ".cmake", ".js")
SKIP_DIRS = {"__pycache__", "fuzz-regressions"}


def is_code(path):
    return path.is_file() and path.name.endswith(CODE)


def folders(root):
    """Every folder of the trees that holds code (directly), in tree order."""
    found = []
    for tree in TREES:
        base = root / tree
        if not base.is_dir():
            continue
        for d in [base] + sorted(p for p in base.rglob("*") if p.is_dir()):
            if SKIP_DIRS & set(d.relative_to(root).parts):
                continue
            if any(is_code(f) for f in d.iterdir()):
                found.append(d)
    return found


def first_sentence(text):
    """The text up to its first full stop that ends a sentence (not "e.g.", "3.4" or "a.cpp")."""
    text = " ".join(text.split())
    for m in re.finditer(r"[.!?](?=\s|$)", text):
        before = text[:m.start()]
        if re.search(r"(\be\.g|\bi\.e|\betc|\bvs|\bcf|\bNo)$", before):
            continue
        return text[:m.end()]
    return text


def top_comment(path):
    """The file's own top comment (its leading // or # lines, or a Python docstring)."""
    lines = path.read_text(errors="replace").split("\n")
    if lines and lines[0].startswith("#!"):
        lines = lines[1:]
    text = "\n".join(lines).lstrip()
    if path.suffix == ".py" and text.startswith(('"""', "'''")):
        quote = text[:3]
        return text[3:text.find(quote, 3)]
    marker = "//" if path.name.endswith((".cpp", ".hpp", ".hpp.in", ".js")) else "#"
    comment = []
    for line in text.split("\n"):
        s = line.strip()
        if not s.startswith(marker):
            break
        comment.append(s[len(marker):].strip())
    return " ".join(comment)


def readme_paragraph(folder):
    """The first paragraph of the folder's README.md (after its title), or None."""
    readme = folder / "README.md"
    if not readme.is_file():
        return None
    paragraphs = [p for p in re.split(r"\n\s*\n", readme.read_text()) if p.strip()]
    body = [p for p in paragraphs if not p.lstrip().startswith("#")]
    return " ".join(body[0].split()) if body else None


def libraries(root):
    """[(name, [public dependencies])] in the order CMakeLists.txt declares the libraries."""
    text = (root / "CMakeLists.txt").read_text()
    names = re.findall(r"^proxseg_library\((\w+)", text, re.M)
    deps = {}
    for name in names:
        m = re.search(r"target_link_libraries\(proxseg_%s\s+PUBLIC([^)]*?)(?:PRIVATE|\))" % name,
                      text)
        deps[name] = re.findall(r"proxseg_(\w+)", m.group(1)) if m else []
    return [(n, deps[n]) for n in names]


def folder_label(root, folder, dirs):
    """The folder as the picture shows it: its path where its parent is not shown, else its
    name, indented under the parent."""
    rel = folder.relative_to(root)
    depth = 0
    parent = folder.parent
    while parent in dirs:
        depth += 1
        parent = parent.parent
    shown = rel.as_posix() if depth == 0 else folder.name
    return "  " * depth + shown + "/"


def layers_block(root, dirs, errors):
    out = ["```text", "The libraries, each linking only those before it (CMakeLists.txt):", ""]
    for name, deps in libraries(root):
        on = ", ".join("proxseg::" + d for d in deps) if deps else "no other part"
        out.append(f"  proxseg::{name:<12} src/{name + '/':<13} include/proxseg/{name + '/':<13}"
                   f"links {on}")
    out += ["  (src/util/ holds header-only helpers any part may include; they include none)",
            "", "The folders (each one's README.md says what lives there and what it may include):",
            ""]
    for d in dirs:
        rel = d.relative_to(root).as_posix()
        para = readme_paragraph(d)
        if para is None:
            errors.append(f"{rel}/README.md is missing: say what lives there and what it may "
                          f"include")
            para = ""
        out.append(f"  {folder_label(root, d, dirs):<24}{first_sentence(para)}")
    out.append("```")
    return out


def files_block(root, dirs, errors):
    out = []
    for d in dirs:
        rel = d.relative_to(root).as_posix()
        out += ["", f"### {rel}/", "", readme_paragraph(d) or "", "", "| file | concept |",
                "|---|---|"]
        for f in sorted(p for p in d.iterdir() if is_code(p)):
            concept = first_sentence(top_comment(f))
            if not concept:
                errors.append(f"{f.relative_to(root).as_posix()}: no top comment saying what it "
                              f"holds")
            concept = concept.replace("|", "\\|")
            out.append(f"| `{f.relative_to(root).as_posix()}` | {concept} |")
    return out[1:]


def generate(root, doc, errors):
    dirs = folders(root)
    for name, lines in (("layers", layers_block(root, dirs, errors)),
                        ("files", files_block(root, dirs, errors))):
        begin, end = f"<!-- generated: {name} -->", f"<!-- end generated: {name} -->"
        if begin not in doc or end not in doc:
            errors.append(f"docs/architecture.md: no {begin} ... {end}")
            continue
        head, rest = doc.split(begin, 1)
        doc = head + begin + "\n" + "\n".join(lines) + "\n" + end + rest.split(end, 1)[1]
    return doc


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    root = pathlib.Path(args[0] if args else pathlib.Path(__file__).resolve().parent.parent)
    path = root / "docs" / "architecture.md"
    doc = path.read_text()
    errors = []
    new = generate(root, doc, errors)
    for e in errors:
        print(e)
    if "--check" in argv:
        if new != doc:
            print("docs/architecture.md is not what scripts/architecture-map.py writes "
                  "(run it to update):")
            sys.stdout.writelines(difflib.unified_diff(doc.splitlines(True), new.splitlines(True),
                                                       "docs/architecture.md", "generated", n=0))
            return 1
        return 1 if errors else 0
    if new != doc:
        path.write_text(new)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
