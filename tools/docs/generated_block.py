# SPDX-License-Identifier: Apache-2.0
"""Rewrites one <!-- generated:NAME --> ... <!-- /generated --> block of a doc: the one place the
tools/docs scripts replace a block, so that a doc without the block fails the same way everywhere.
Python 3 standard library only."""
import re
import sys


def replace_block(doc, name, lines):
    """Replaces the body of `doc`'s generated:`name` block with `lines` (a list of lines); exits naming the doc
    and the block when it has none."""
    block = re.compile(rf"^<!-- generated:{re.escape(name)} -->\n.*?^<!-- /generated -->$", re.S | re.M)
    text = open(doc).read()
    if not block.search(text):
        sys.exit(f"{doc}: no <!-- generated:{name} --> block")
    body = "\n".join(lines)
    text = block.sub(lambda m: f"<!-- generated:{name} -->\n{body}\n<!-- /generated -->", text)
    open(doc, "w").write(text)
