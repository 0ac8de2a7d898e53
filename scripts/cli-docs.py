#!/usr/bin/env python3
"""The man page (proxseg.1) and the bash completion of the proxseg CLI, made from its --help,
so that they say exactly what the program accepts.

Usage: scripts/cli-docs.py PROXSEG OUT_DIR   writes OUT_DIR/proxseg.1.gz and OUT_DIR/proxseg.bash
"""

import datetime
import gzip
import os
import re
import subprocess
import sys
from pathlib import Path


def help_of(program, *words):
    r = subprocess.run([program, *words, "--help"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"cli-docs.py: {program} {' '.join(words)} --help: exit {r.returncode}\n{r.stderr}")
    return r.stdout


def parse(text):
    """(description, usage, [[names, type, help, heading]], [(command, help)]) of one --help.

    Options are listed under headings (CLI11's option groups: "Input:", "Output:", ...,
    "Positionals:"), commands under "Subcommands:"."""
    lines = text.splitlines()
    description = lines[0].strip() if lines and not lines[0].startswith("Usage") else ""
    usage = next((l[len("Usage: "):] for l in lines if l.startswith("Usage: ")), "")
    options, commands, section, last = [], [], None, None
    for line in lines:
        heading = re.match(r"^(\S[^:]*):$", line)
        if heading and not line.startswith("Usage"):
            section = heading.group(1)
            continue
        if section == "Subcommands":
            m = re.match(r"^  (\S+)\s+(.*)$", line)
            if m:
                commands.append((m.group(1), m.group(2)))
        elif section is not None:
            m = re.match(r"^  (\S.*?)(?:\s{2,}(.*))?$", line)
            if m:
                spec, text_ = m.group(1), m.group(2) or ""
                names = spec.split(" ")[0]
                kind = " ".join(spec.split(" ")[1:])
                last = [names, kind, text_, section]
                options.append(last)
            elif line.startswith("    ") and last is not None:
                last[2] = (last[2] + " " + line.strip()).strip()
    return description, usage, options, commands


# Real uses, each a command line and what it does (the man page's EXAMPLES). The first ones need
# nothing but proxseg: the CLI tests run them as written.
EXAMPLES = [
    ("Write the built-in synthetic tabletop scene (ground truth in field label) and segment it: "
     "out/scene.pcd, out/scene.png and out/scene.json.",
     ["proxseg synth -o scene.pcd", "proxseg segment scene.pcd -o out/scene"]),
    ("Segment a cloud from standard input (PCD or PLY, told apart by content) and print only "
     "the JSON report on stdout; nothing is written.",
     ["proxseg synth -o - | proxseg segment - --outputs json -o - > report.json"]),
    ("Compute without writing any file; print the one-line summary.",
     ["proxseg segment scene.pcd --outputs none"]),
    ("The 3D page of a result, one HTML file that any browser opens.",
     ["proxseg view out/scene"]),
    ("Build a model database from view clouds, or render views of a coloured mesh in "
     "millimetres, then name every object of a scene.",
     ["proxseg db add models --name mug mug-1.pcd mug-2.pcd",
      "proxseg db render models --name ape --units mm obj_000001.ply",
      "proxseg recognize scene.pcd --db models -o out/scene"]),
    ("Segment a whole dataset, frames two at a time, writing only 16-bit label images and "
     "reports; shard 1 of 4 of it, resumable; then merge the shards' summaries.",
     ["proxseg segment --batch frames/ -o out/ --outputs labels,json --threads 2",
      "proxseg segment --batch frames/ -o out/ --shard 1/4 --resume",
      "proxseg summary out/"]),
    ("An RGB-D pair of a YCB-Video frame, with its camera from the meta file.",
     ["proxseg segment --colour 000001-color.png --depth 000001-depth.png "
      "--meta 000001-meta.json -o out/000001"]),
    ("Every parameter, its default, range, the paper's value and its flag.",
     ["proxseg params segmentation"]),
]


def roff(text):
    return text.replace("\\", "\\\\").replace("-", "\\-").replace("'", "\\(aq")


def option_list(options):
    """The options of one --help under their headings (the option groups)."""
    out, heading = [], None
    for names, kind, text, group in options:
        if group != heading:
            heading = group
            out += [".PP", f"\\fI{roff(group)}:\\fR"]
        out += [".TP", f"\\fB{roff(names)}\\fR {roff(kind)}".rstrip(), roff(text)]
    return out


def man_page(program, tree, version):
    # SOURCE_DATE_EPOCH: reproducible builds date the page by the source, not the build.
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    today = (datetime.datetime.fromtimestamp(int(epoch), datetime.timezone.utc).date()
             if epoch else datetime.date.today()).isoformat()
    out = [f'.TH PROXSEG 1 "{today}" "proxseg {version}" "User Commands"',
           ".SH NAME", "proxseg \\- " + roff(tree[()][0].split(": ", 1)[-1]),
           ".SH SYNOPSIS", ".B proxseg", "[\\fIOPTIONS\\fR] \\fICOMMAND\\fR [\\fIOPTIONS\\fR]",
           ".SH DESCRIPTION",
           roff("proxseg segments an RGB-D point cloud into regions without training, picks out "
                "the candidate objects and names each from a database of model views, with its "
                "pose. Logs go to stderr, results to stdout or files. Exit status: 0 success, "
                "1 bad input, 2 usage error, 130 an interrupted batch."),
           ".SH OPTIONS"]
    out += option_list(tree[()][2])
    out.append(".SH COMMANDS")
    for words in sorted(tree):
        if not words:
            continue
        description, usage, options, commands = tree[words]
        out += [".SS " + roff("proxseg " + " ".join(words)), roff(description),
                ".PP", "Usage: " + roff(usage)]
        out += option_list([o for o in options if o[0] != "-h,--help"])
    out.append(".SH EXAMPLES")
    for what, lines in EXAMPLES:
        out += [".PP", roff(what), ".PP", ".RS", ".nf"]
        out += [roff(line) for line in lines]
        out += [".fi", ".RE"]
    out += [".SH FILES", roff("/usr/share/doc/proxseg-doc/ (Debian package proxseg-doc; "
                              "share/doc/proxseg-doc/ under another install prefix, docs/ in the "
                              "source) holds the documentation the commands name as docs/: "
                              "parameters.md lists every parameter (proxseg params), batch.md "
                              "the batch outputs, database.md the model database file, "
                              "method.md the method; api/cpp/index.html and "
                              "api/python/proxseg.html are the API references."),
            ".SH SEE ALSO", "pcl_viewer(1)"]
    return "\n".join(out) + "\n"


def completion(tree):
    cases = []
    for words in sorted(tree, key=len, reverse=True):
        _, _, options, commands = tree[words]
        flags = sorted({n for names, *_ in options for n in names.split(",") if n.startswith("-")})
        subs = [c for c, _ in commands]
        key = " ".join(words)
        cases.append(f'    "{key}") words="{" ".join(subs + flags)}" ;;')
    return """# bash completion of proxseg (made by scripts/cli-docs.py from its --help)
_proxseg() {
  local cur=${COMP_WORDS[COMP_CWORD]} path="" w i
  for ((i = 1; i < COMP_CWORD; i++)); do
    w=${COMP_WORDS[i]}
    [[ $w == -* ]] && continue
    case "${path:+$path }$w" in
%s
    esac
  done
  local words
  case "$path" in
%s
    *) words="" ;;
  esac
  if [[ $cur == -* || -n $words ]]; then
    COMPREPLY=($(compgen -W "$words" -- "$cur"))
  fi
  [[ $cur != -* ]] && COMPREPLY+=($(compgen -f -- "$cur"))
}
complete -o filenames -F _proxseg proxseg
""" % ("\n".join(f'      "{" ".join(w)}") path="{" ".join(w)}" ;;' for w in tree if w),
       "\n".join(cases))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    program, out_dir = sys.argv[1], Path(sys.argv[2])
    tree, todo = {}, [()]
    while todo:
        words = todo.pop()
        tree[words] = parse(help_of(program, *words))
        todo += [words + (c,) for c, _ in tree[words][3]]
    version = subprocess.run([program, "--version"], capture_output=True, text=True).stdout.split()
    out_dir.mkdir(parents=True, exist_ok=True)
    page = man_page(program, tree, version[1] if len(version) > 1 else "?")
    # Compressed as Debian installs man pages; mtime 0 keeps the file reproducible.
    with gzip.GzipFile(out_dir / "proxseg.1.gz", "wb", mtime=0) as out:
        out.write(page.encode())
    (out_dir / "proxseg.bash").write_text(completion(tree))


if __name__ == "__main__":
    main()
