"""``retrokit docs [TOPIC]``: print one of retrokit's guides, which ship inside the package.

Help texts and errors point at guides as ``retrokit docs TOPIC``: that works
from a wheel, where no ``docs/`` folder sits beside the package.
"""

from __future__ import annotations

import argparse
import sys


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``docs`` command."""
    parser = subparsers.add_parser(
        "docs",
        help="print one of retrokit's guides (no TOPIC: list them)",
        description="Print one of retrokit's guides (the docs/*.md files of its repository, shipped inside the "
        "package), in Markdown. With no TOPIC, list the guides and what each covers.",
    )
    parser.add_argument("topic", metavar="TOPIC", nargs="?", help="the guide to print, e.g. integrate or scenarios")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Print the guide, or the list of guides."""
    from retrokit.paths import doc_path, doc_topics

    if args.topic is not None:
        sys.stdout.write(doc_path(args.topic).read_text(encoding="utf-8"))
        return 0
    topics = doc_topics()
    width = max((len(topic) for topic in topics), default=0)
    for topic in topics:
        title = doc_path(topic).read_text(encoding="utf-8").partition("\n")[0].lstrip("# ").strip()
        print(f"{topic:<{width}}  {title}")
    print("Print one with: retrokit docs TOPIC")
    return 0


#: Full command lines, shown at the end of --help (retrokit/cli.py); tests/test_cli_teaches.py parses each.
EXAMPLES = [
    "retrokit docs                      # the guides, and what each covers",
    "retrokit docs integrate            # print one: integrating a game (states, movies, checks)",
    "retrokit docs scenarios            # rewards and done conditions",
]
