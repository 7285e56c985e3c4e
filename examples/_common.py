"""Shared by the numbered examples: the command line (--small for a quick run, --out for the outputs)."""
import argparse
import os

import lidarshop


def parse_args(description):
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", default="example_output", help="folder for the files written")
    parser.add_argument("--small", action="store_true", help="a coarse scan (seconds; the tests use it)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    return args


def mailbox_scene(small):
    """The built-in mailbox scene as a dict; --small scans it with a quarter of the rays."""
    scene = lidarshop.builtin_scene("mailbox")
    if small:
        scene["scanner"]["columns"] //= 2
        scene["scanner"]["rows"] //= 2
    return scene
