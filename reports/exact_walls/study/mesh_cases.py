#!/usr/bin/env python3
"""Writes the study's mesh variant of the shipped screw, beside this file: every [[body]]'s
`cell_size` replaced by `contact = "mesh"` (a scene override cannot remove a field). The silo
case is met on its triangles as shipped.
Usage: python3 reports/exact_walls/study/mesh_cases.py"""
import os
import re

here = os.path.dirname(os.path.abspath(__file__))
cases = os.path.join(here, "..", "..", "..", "validation", "cases")


def with_mesh_contact(text):
    """A case's text with every body's `cell_size` (and its comment lines) replaced by
    `contact = "mesh"`."""
    return re.sub(r"cell_size = [0-9.e-]+[^\n]*\n(?:[ ]+#[^\n]*\n)*", 'contact = "mesh"\n', text)


if __name__ == "__main__":
    for name in ("screw_feeder_hertz",):
        text = open(os.path.join(cases, name + ".toml")).read()
        with open(os.path.join(here, name + "_mesh.toml"), "w") as f:
            f.write(f"# Written by mesh_cases.py from validation/cases/{name}.toml: do not edit.\n"
                    + with_mesh_contact(text))
