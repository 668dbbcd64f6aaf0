"""Convex pieces of a robot's collision meshes, for an embodiment's ``collision_pieces``.

SAPIEN's URDF loader takes one convex hull of each collision mesh. For most links that is
close enough; for a gripper whose fixed jaw is printed in one piece with the wrist (the
SO-101's), the hull fills the space between the jaws with a slanted face that wedges a
grasped object down into the table. CoACD (seeded, so the pieces are reproducible) cuts
such a mesh into convex pieces; the embodiment file then names the folder they are in:

    python -m fsvla.embodiments.pieces MESH.stl [...] --out FOLDER [--max-pieces 16]

writes ``FOLDER/<mesh stem>/piece_NN.obj`` for each mesh, and the embodiment's robot
takes ``collision_pieces = { "MESH.stl" = "FOLDER/<mesh stem>" }`` (relative to its file).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path


def write_convex_pieces(mesh: Path, folder: Path, max_pieces: int = 16) -> list[Path]:
    """Decompose ``mesh`` with CoACD and write its pieces as ``folder/piece_NN.obj``
    (the folder's earlier pieces removed first); the files written."""
    import trimesh

    from fsvla.compiler.assets.decomposition import coacd_decomposition

    loaded = trimesh.load(mesh, force="mesh")
    pieces = coacd_decomposition(loaded, max_pieces)
    if pieces is None:
        raise RuntimeError("convex decomposition needs CoACD: pip install coacd")
    folder.mkdir(parents=True, exist_ok=True)
    for old in folder.glob("piece_*.obj"):
        old.unlink()
    written = []
    for index, piece in enumerate(pieces):
        path = folder / f"piece_{index:02d}.obj"
        piece.export(path)
        written.append(path)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fsvla.embodiments.pieces",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("meshes", nargs="+", type=Path, help="collision mesh files (.stl, .obj, .dae)")
    parser.add_argument("--out", required=True, type=Path, help="folder to write <mesh stem>/ folders into")
    parser.add_argument("--max-pieces", type=int, default=16)
    args = parser.parse_args(argv)
    for mesh in args.meshes:
        if not mesh.is_file():
            parser.error(f"{mesh}: no such mesh file")
        written = write_convex_pieces(mesh, args.out / mesh.stem, args.max_pieces)
        sys.stdout.write(f"{mesh.name}: {len(written)} convex pieces in {args.out / mesh.stem}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
