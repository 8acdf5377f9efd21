"""Opens a run's frames.xdmf in ParaView's own reader and prints what it sees: points, time steps, bounds and
every point field with its components and range at the last frame. A check that ParaView reads the output as
written (2D and 3D), without a display:

    pvpython --force-offscreen-rendering tools/paraview_check.py OUT/frames.xdmf [...]

pvpython comes with Debian's paraview package (not a dependency of sphrefine; checked with ParaView 5.11).
Exits non-zero if a file holds no points or no time steps.
"""
import sys

from paraview.simple import XDMFReader  # pylint: disable=import-error


def main(paths):
    bad = 0
    for path in paths:
        reader = XDMFReader(FileNames=[path])
        reader.UpdatePipelineInformation()
        times = list(reader.TimestepValues or [])
        reader.UpdatePipeline(times[-1] if times else 0.0)
        info = reader.GetDataInformation()
        points = info.GetNumberOfPoints()
        print(f"{path}: {points} points, {len(times)} time steps, bounds "
              f"{[round(b, 4) for b in info.GetBounds()]}")
        for name in reader.PointData.keys():
            array = reader.PointData[name]
            print(f"  {name}: {array.GetNumberOfComponents()} components, range "
                  f"{[round(x, 4) for x in array.GetRange(-1)]}")
        if points == 0 or not times:
            bad += 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
