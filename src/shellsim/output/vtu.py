"""``<name>.pvd`` indexing one ``<frames>/<name>_NNNN.vtu`` per frame; the index is
rewritten atomically after every frame, and lists a frame only once it is whole."""

from __future__ import annotations

import shutil
from pathlib import Path
from xml.etree import ElementTree as ET

from .encoding import Encoding
from .folder import refuse_link, replacing, subfolder, write_atomically

FRAMES_DIR = "frames"


def pvd_entries(path: Path) -> list[tuple[float, str]]:
    """(time, file) of each frame a ``.pvd`` index lists, in its order."""
    return [(float(item.get("timestep")), item.get("file")) for item in ET.parse(path).getroot().iter("DataSet")]


class VtuSeries:
    """``<name>.pvd`` + one VTU per frame in ``folder`` (frames in ``frames`` for the
    results, ``<name>_frames`` for another series), on ``mesh`` (its points (P, 3), cells
    (C, k) and cell type), numbers stored as ``encoding`` says; going on from a checkpoint,
    after the first ``kept`` frames of the series there."""

    def __init__(self, folder: Path, mesh, encoding: Encoding, name: str = "results", kept: int | None = None):
        self.name = name
        self.path = folder / f"{name}.pvd"
        frames = FRAMES_DIR if name == "results" else f"{name}_{FRAMES_DIR}"
        self.frames = refuse_link(folder / frames)
        self.mesh = mesh
        self.encoding = encoding
        self.entries: list[tuple[float, str]] = []
        if kept is not None:
            listed = pvd_entries(self.path)
            self.entries = listed[:kept]
            for _, file in listed[kept:]:
                (folder / file).unlink(missing_ok=True)
            return
        if self.frames.exists():  # frames of an earlier run would be listed by nobody
            shutil.rmtree(self.frames)
        subfolder(folder, frames)

    def write(self, t: float, point_data: dict, cell_data: dict) -> None:
        """Add the frame at time ``t``: fields (P,) or (P, k) on the points, (C,) or (C, k)
        on the cells."""
        import meshio

        floats = self.encoding.floats
        name = f"{self.frames.name}/{self.name}_{len(self.entries):04d}.vtu"
        with replacing(self.path.parent / name) as partial:
            meshio.write(partial, meshio.Mesh(
                floats(self.mesh.points), [(self.mesh.cell_type, self.mesh.cells)],
                point_data={key: floats(values) for key, values in point_data.items()},
                cell_data={key: [floats(values)] for key, values in cell_data.items()}),
                file_format="vtu", compression="zlib" if self.encoding.compress else None)
        self.entries.append((float(t), name))
        root = ET.Element("VTKFile", type="Collection", version="0.1")
        collection = ET.SubElement(root, "Collection")
        for time, file in self.entries:
            ET.SubElement(collection, "DataSet", timestep=repr(time), part="0", file=file)
        write_atomically(self.path, ET.tostring(root, xml_declaration=True))

    def close(self) -> None:
        pass
