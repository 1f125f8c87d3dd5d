"""``<name>.xdmf`` + ``<name>.h5``: a time series that ParaView's three XDMF readers (XDMF
Reader, Xdmf3ReaderS, Xdmf3ReaderT) and meshio read, its XML rewritten atomically after
every frame so a run that stops keeps every frame written so far.

Every frame's grid names the mesh's topology and geometry itself, pointing at the one copy
of each in the HDF5 file. A separate mesh grid, included into the frames through XInclude
(meshio's own layout), was shown by ParaView's legacy reader as an undeformed copy beside
the frames, and by its Xdmf3 readers as nothing at all.
"""

from __future__ import annotations

import copy
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from .encoding import Encoding
from .folder import refuse_link, write_atomically

#: XDMF's topology type and nodes per cell of each cell type written.
TOPOLOGY = {"quad": ("Quadrilateral", 4), "hexahedron": ("Hexahedron", 8), "line": ("Polyline", 2)}
#: XDMF's attribute type by the number of components; any other count is a Matrix. A
#: symmetric tensor's six components go as a Matrix: every ParaView reader then names them
#: XX, YY, ZZ, XY, YZ, XZ, where its legacy reader turns a Tensor6 into nine unnamed ones.
ATTRIBUTE_TYPE = {1: "Scalar", 3: "Vector"}


class XdmfSeries:
    """``<name>.xdmf`` + ``<name>.h5`` in ``folder``, on ``mesh`` (its points (P, 3),
    cells (C, k) and cell type), numbers stored as ``encoding`` says; going on from a
    checkpoint, after the first ``kept`` frames of the series there."""

    def __init__(self, folder: Path, mesh, encoding: Encoding, name: str = "results", kept: int | None = None):
        import h5py

        self.path = folder / f"{name}.xdmf"
        self.encoding = encoding
        self._h5_name = f"{name}.h5"
        if kept is not None:
            self._h5 = h5py.File(refuse_link(folder / self._h5_name), "a")
            self._go_on_after(kept)
            return
        self._h5 = h5py.File(refuse_link(folder / self._h5_name), "w")
        topology_type, corners = TOPOLOGY[mesh.cell_type]
        self._topology = ET.Element("Topology", TopologyType=topology_type, NumberOfElements=str(len(mesh.cells)),
                                    NodesPerElement=str(corners))
        self._item(self._topology, "mesh/cells", np.ascontiguousarray(mesh.cells, dtype=np.int32))
        self._geometry = ET.Element("Geometry", GeometryType="XYZ")
        self._item(self._geometry, "mesh/points", encoding.floats(mesh.points))
        self._root = ET.Element("Xdmf", Version="3.0")
        self._frames = ET.SubElement(ET.SubElement(self._root, "Domain"), "Grid", Name=name, GridType="Collection",
                                     CollectionType="Temporal")
        self.count = 0

    def _go_on_after(self, kept: int) -> None:
        """The series as written, its frames after the first ``kept`` dropped."""
        self._root = ET.parse(self.path).getroot()
        self._frames = self._root.find("Domain/Grid")
        frames = self._frames.findall("Grid")
        for grid in frames[kept:]:
            self._frames.remove(grid)
        for index in range(kept, len(frames)):
            self._h5.pop(f"frames/{index}", None)
        self._topology, self._geometry = frames[0].find("Topology"), frames[0].find("Geometry")
        self.count = kept

    def _item(self, parent: ET.Element, path: str, values: np.ndarray) -> None:
        """Store ``values`` at ``path`` in the HDF5 file and point ``parent`` at it."""
        compressed = dict(compression="gzip", shuffle=True) if self.encoding.compress and values.size else {}
        self._h5.create_dataset(path, data=values, **compressed)
        item = ET.SubElement(parent, "DataItem", DataType="Float" if values.dtype.kind == "f" else "Int",
                             Precision=str(values.dtype.itemsize), Dimensions=" ".join(map(str, values.shape)),
                             Format="HDF")
        item.text = f"{self._h5_name}:/{path}"

    def write(self, t: float, point_data: dict, cell_data: dict) -> None:
        """Add the frame at time ``t``: fields (P,) or (P, k) on the points, (C,) or (C, k)
        on the cells."""
        grid = ET.SubElement(self._frames, "Grid", Name=f"frame_{self.count:04d}", GridType="Uniform")
        ET.SubElement(grid, "Time", Value=repr(float(t)))
        grid.extend([copy.copy(self._topology), copy.copy(self._geometry)])
        for center, fields in (("Node", point_data), ("Cell", cell_data)):
            for name, values in fields.items():
                columns = 1 if values.ndim == 1 else values.shape[1]
                attribute = ET.SubElement(grid, "Attribute", Name=name, Center=center,
                                          AttributeType=ATTRIBUTE_TYPE.get(columns, "Matrix"))
                self._item(attribute, f"frames/{self.count}/{name}", self.encoding.floats(values))
        self._h5.flush()
        self.count += 1
        write_atomically(self.path, ET.tostring(self._root))

    def close(self) -> None:
        self._h5.close()
