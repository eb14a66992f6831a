# Sphinx configuration of the diefill manual (docs/build builds it).
#
# The source directory is the repository root, so that the top-level README, the pages of
# docs/ and the README of every tutorial are pages of one site and the relative links
# between them (e.g. docs/user-guide.md -> ../tutorials/dieFilling/README.md) work both
# on GitHub and in the HTML.  Only the files named in include_patterns are read.
project = "diefill"
author = "the diefill authors"
copyright = "the diefill authors"

extensions = ["myst_parser"]
source_suffix = {".md": "markdown"}
root_doc = "docs/index"

include_patterns = [
    "README.md",
    "docs/*.md",
    "bench/README.md",
    "tutorials/**/README.md",
]
# tutorials/calibration/full: the full calibration's work folder (its case copies hold READMEs)
exclude_patterns = ["build", "install", "platforms", "ThirdParty", "run", ".cache", "tutorials/calibration/full/**"]

# Headings get anchors so that links like user-guide.md#running-in-parallel resolve.
myst_heading_anchors = 3
# No dollarmath: the pages write formulas in plain text, and a $ in prose stays a $.
myst_enable_extensions = ["colon_fence"]

html_theme = "alabaster"
html_title = "diefill manual"
html_theme_options = {"fixed_sidebar": True, "page_width": "1100px", "body_max_width": "none"}
html_show_sourcelink = False
