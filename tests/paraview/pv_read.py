"""Run by pvbatch for tests/paraview/test_paraview.py: opens XDMF sidecars with ParaView's
readers and writes what each reader produced as JSON, for the test to compare with h5py.

    pvbatch [--symmetric] pv_read.py SPEC.json OUT.json

SPEC: {"cases": [{"file": ..., "reader": "XDMFReader" | "Xdmf3ReaderS" | "Xdmf3ReaderT" |
"OpenDataFile", "slice": {"origin": [x, y, z], "normal": [x, y, z]} (optional)}, ...]}.
OUT: one entry per case: the reader's output (class, extent, bounds, coordinates, point
arrays with their VTK types and values) and the slice's (points, arrays). Under mpirun with
--symmetric every rank runs this and writes its own piece to OUT.RANK."""
import json
import sys

import paraview.simple as pv
from paraview import servermanager
from vtk.util.numpy_support import vtk_to_numpy

FILE_PROPERTY = {"XDMFReader": "FileNames", "Xdmf3ReaderS": "FileName", "Xdmf3ReaderT": "FileName"}


def point_arrays(data):
    pd = data.GetPointData()
    return {pd.GetArrayName(i): {"type": pd.GetArray(i).GetDataTypeAsString(),
                                 "values": vtk_to_numpy(pd.GetArray(i)).tolist()}
            for i in range(pd.GetNumberOfArrays())}


def only_block(data):
    """The dataset itself, also when a reader wraps it in a multiblock."""
    while data is not None and data.IsA("vtkMultiBlockDataSet"):
        data = data.GetBlock(0)
    return data


def read(case):
    if case["reader"] == "OpenDataFile":
        reader = pv.OpenDataFile(case["file"])
    else:
        reader = getattr(pv, case["reader"])(**{FILE_PROPERTY[case["reader"]]: [case["file"]]})
    reader.UpdatePipeline()
    data = only_block(reader.GetClientSideObject().GetOutputDataObject(0))
    out = {"reader": reader.GetXMLName(), "class": data.GetClassName(), "extent": list(data.GetExtent()),
           "bounds": list(data.GetBounds()),
           "coordinates": [vtk_to_numpy(c).tolist() for c in
                           (data.GetXCoordinates(), data.GetYCoordinates(), data.GetZCoordinates())],
           "arrays": point_arrays(data)}
    if "slice" in case:
        cut = pv.Slice(Input=reader)
        cut.SliceType = "Plane"
        cut.SliceType.Origin = case["slice"]["origin"]
        cut.SliceType.Normal = case["slice"]["normal"]
        cut.UpdatePipeline()
        sliced = only_block(cut.GetClientSideObject().GetOutputDataObject(0))
        out["slice"] = {"class": sliced.GetClassName(),
                        "points": vtk_to_numpy(sliced.GetPoints().GetData()).tolist() if sliced.GetPoints() else [],
                        "arrays": point_arrays(sliced)}
        pv.Delete(cut)
    pv.Delete(reader)
    return out


def main():
    spec_path, out_path = sys.argv[1], sys.argv[2]
    with open(spec_path) as f:
        cases = json.load(f)["cases"]
    results = [read(case) for case in cases]
    controller = servermanager.vtkProcessModule.GetProcessModule()
    if controller.GetNumberOfLocalPartitions() > 1:
        out_path += f".{controller.GetPartitionId()}"
    with open(out_path, "w") as f:
        json.dump(results, f)


main()
