#!/usr/bin/env python3
"""Independent DICOM reference for tests/unit/test_dicom.cpp (pydicom + numpy,
no vdbdag code).

  dicom_reference.py list FOLDER
      JSON on stdout: {"series": {UID: number of image files}, "non_dicom": [files]}
  dicom_reference.py stack FOLDER UID OUT
      Stacks the files of series UID (found recursively) sorted by
      ImagePositionPatient . normal, normal = cross(row dir, col dir) from
      ImageOrientationPatient. Writes OUT.raw (the stored samples,
      pixel_array, little endian, x fastest) and OUT.json: dims [cols, rows,
      slices], origin (IPP of the first slice, LPS mm), axes (row dir *
      column spacing, col dir * row spacing, (IPP_last - IPP_first)/(n-1) or
      normal * SliceThickness for one slice), slope, intercept, dtype,
      files and positions (along the normal) in order.
  dicom_reference.py multiframe FOLDER UID OUT.dcm MODE
      Writes the series as one multi-frame file (frames in reverse order),
      MODE "perframe": Per-frame Functional Groups (Plane Position per
      frame, the rest shared); MODE "spacing": Image Position of the first
      frame + Spacing Between Slices, frames in order.
  dicom_reference.py bigendian OUTDIR FILE...
      Rewrites each file in Explicit VR Big Endian (1.2.840.10008.1.2.2).
"""
import json
import os
import sys

import numpy as np
import pydicom
from pydicom.dataset import Dataset
from pydicom.sequence import Sequence


def files_of(folder):
    out = []
    for root, _, names in os.walk(folder):
        for n in names:
            out.append(os.path.join(root, n))
    return sorted(out)


def read_series(folder, uid):
    items = []
    for f in files_of(folder):
        try:
            ds = pydicom.dcmread(f)
        except Exception:
            continue
        if ds.get("SeriesInstanceUID") != uid or "PixelData" not in ds:
            continue
        items.append((f, ds))
    if not items:
        sys.exit(f"no files of series {uid} in {folder}")
    iop = np.array([float(v) for v in items[0][1].ImageOrientationPatient])
    row, col = iop[:3], iop[3:]
    normal = np.cross(row, col)
    normal /= np.linalg.norm(normal)
    items.sort(key=lambda it: float(np.dot([float(v) for v in it[1].ImagePositionPatient], normal)))
    return items, row, col, normal


def main():
    mode = sys.argv[1]
    if mode == "list":
        series, non_dicom = {}, []
        for f in files_of(sys.argv[2]):
            try:
                ds = pydicom.dcmread(f, stop_before_pixels=True)
            except Exception:
                non_dicom.append(f)
                continue
            uid = ds.get("SeriesInstanceUID")
            if uid is not None and "Rows" in ds:
                series[uid] = series.get(uid, 0) + 1
        json.dump({"series": series, "non_dicom": non_dicom}, sys.stdout)
        return

    if mode == "bigendian":
        for f in sys.argv[3:]:
            ds = pydicom.dcmread(f)
            a = ds.pixel_array
            ds.file_meta.TransferSyntaxUID = pydicom.uid.ExplicitVRBigEndian
            ds.is_little_endian, ds.is_implicit_VR = False, False
            ds.PixelData = a.astype(a.dtype.newbyteorder(">")).tobytes()
            ds["PixelData"].VR = "OW"
            ds.save_as(os.path.join(sys.argv[2], os.path.basename(f)), write_like_original=False)
        return

    folder, uid, out = sys.argv[2], sys.argv[3], sys.argv[4]
    items, row, col, normal = read_series(folder, uid)
    first = items[0][1]
    if mode == "stack":
        planes = [ds.pixel_array for _, ds in items]
        stack = np.stack(planes)  # (slices, rows, cols): x fastest
        stack = stack.astype(stack.dtype.newbyteorder("<"))
        with open(out + ".raw", "wb") as fh:
            fh.write(stack.tobytes())
        ipp = [np.array([float(v) for v in ds.ImagePositionPatient]) for _, ds in items]
        ps = [float(v) for v in first.PixelSpacing]
        if len(items) > 1:
            axis2 = (ipp[-1] - ipp[0]) / (len(items) - 1)
        else:
            axis2 = normal * float(first.get("SliceThickness", 1) or 1)
        meta = {
            "dims": [int(first.Columns), int(first.Rows), len(items)],
            "origin": ipp[0].tolist(),
            "axes": [(row * ps[1]).tolist(), (col * ps[0]).tolist(), axis2.tolist()],
            "slope": float(first.get("RescaleSlope", 1)),
            "intercept": float(first.get("RescaleIntercept", 0)),
            "dtype": str(stack.dtype),
            "files": [f for f, _ in items],
            "positions": [float(np.dot(p, normal)) for p in ipp],
        }
        with open(out + ".json", "w") as fh:
            json.dump(meta, fh)
        return

    if mode == "multiframe":
        kind = sys.argv[5]
        order = list(reversed(items)) if kind == "perframe" else items
        ds = first.copy()
        ds.NumberOfFrames = len(order)
        ds.PixelData = b"".join(d.pixel_array.astype(d.pixel_array.dtype.newbyteorder("<")).tobytes() for _, d in order)
        ds["PixelData"].VR = "OW"
        ds.SOPInstanceUID = pydicom.uid.generate_uid()
        if kind == "perframe":
            del ds.ImagePositionPatient
            shared = Dataset()
            orient = Dataset()
            orient.ImageOrientationPatient = first.ImageOrientationPatient
            shared.PlaneOrientationSequence = Sequence([orient])
            measures = Dataset()
            measures.PixelSpacing = first.PixelSpacing
            measures.SliceThickness = first.get("SliceThickness", 1)
            shared.PixelMeasuresSequence = Sequence([measures])
            ds.SharedFunctionalGroupsSequence = Sequence([shared])
            frames = []
            for _, d in order:
                fg = Dataset()
                pos = Dataset()
                pos.ImagePositionPatient = d.ImagePositionPatient
                fg.PlanePositionSequence = Sequence([pos])
                frames.append(fg)
            ds.PerFrameFunctionalGroupsSequence = Sequence(frames)
        else:
            ipp = [np.array([float(v) for v in d.ImagePositionPatient]) for _, d in order]
            ds.SpacingBetweenSlices = f"{float(np.dot(ipp[1] - ipp[0], normal)):.10g}"
        ds.save_as(out, write_like_original=False)
        return
    sys.exit("unknown mode " + mode)


if __name__ == "__main__":
    main()
