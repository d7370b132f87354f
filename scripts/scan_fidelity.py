#!/usr/bin/python3
"""Issue 36's figures in one run, against independent readers:
  - the PET series of ../shared/data decoded to .nrrd and .mha against
    pydicom's rescaled values, beside the baseline `decode --stored-values`
    (what every decode wrote before: the stored integers, no rescale);
  - every NIfTI file of ../shared/data/medical/nifti through encode and
    decode -o .nii.gz: nibabel header fields that differ, scl, samples.
    python3 scripts/scan_fidelity.py [--json]
Uses build/vdbdag (or VDBDAG_EXECUTABLE) and a temporary folder."""
import glob, json, os, subprocess, sys, tempfile

import nibabel as nib
import numpy as np
import pydicom

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "tools"))
import scan_reference  # noqa: E402

V = os.environ.get("VDBDAG_EXECUTABLE", os.path.join(ROOT, "build", "vdbdag"))
DATA = os.environ.get("VDBDAG_SHARED_DATA", os.path.join(ROOT, "..", "shared", "data"))


def pet(work):
    folder = os.path.join(DATA, "medical", "dicom", "rsna_2", "PET")
    slices = [d for d in (pydicom.dcmread(f) for f in sorted(glob.glob(folder + "/*"))) if "PixelData" in d]
    normal = np.cross(np.array(slices[0].ImageOrientationPatient[:3], float), np.array(slices[0].ImageOrientationPatient[3:], float))
    slices.sort(key=lambda d: float(np.dot(normal, np.array(d.ImagePositionPatient, float))))
    ref = np.stack([d.pixel_array.astype(np.float64) * float(d.RescaleSlope) + float(d.RescaleIntercept) for d in slices]).astype(np.float32)
    enc = os.path.join(work, "pet.ssvdag")
    subprocess.run([V, "encode", folder, "-o", enc, "-q"], check=True, capture_output=True)
    rows = []
    for name, extra in [("pet.nrrd", []), ("pet.mha", []), ("pet_stored.nrrd", ["--stored-values"])]:
        out = os.path.join(work, name)
        subprocess.run([V, "decode", enc, "-o", out] + extra, check=True, capture_output=True)
        info, data = (scan_reference.nrrd if name.endswith(".nrrd") else scan_reference.metaimage)(out)
        got = np.asarray(data).reshape(ref.shape).astype(np.float64)
        rows.append({"output": name, "options": " ".join(extra), "dtype": info["dtype"], "samples": int(got.size),
                     "differing": int((got != ref).sum()), "max_abs_diff": float(np.abs(got - ref).max())})
    return rows


def nifti(work):
    rows = []
    for f in sorted(glob.glob(os.path.join(DATA, "medical", "nifti", "*.nii*"))):
        name = os.path.basename(f).split(".")[0]
        enc, back = os.path.join(work, name + ".ssvdag"), os.path.join(work, name + "_back.nii.gz")
        r = subprocess.run([V, "encode", f, "-o", enc, "-q"], capture_output=True, text=True)
        if r.returncode:
            rows.append({"file": name, "refused": r.stderr.strip()})
            continue
        subprocess.run([V, "decode", enc, "-o", back], check=True, capture_output=True)
        a, b = nib.load(f), nib.load(back)
        differing = [k for k in a.header.keys() if not np.array_equal(np.asarray(a.header[k]), np.asarray(b.header[k]),
                                                                      equal_nan=np.asarray(a.header[k]).dtype.kind == "f")]
        rows.append({"file": name, "fields": len(a.header.keys()), "differing": differing,
                     "scl_equal": (float(a.dataobj.slope), float(a.dataobj.inter)) == (float(b.dataobj.slope), float(b.dataobj.inter)),
                     "samples_bit_exact": np.asanyarray(a.dataobj.get_unscaled()).tobytes() == np.asanyarray(b.dataobj.get_unscaled()).tobytes(),
                     "shape": list(b.shape)})
    return rows


with tempfile.TemporaryDirectory() as work:
    report = {"pet": pet(work), "nifti": nifti(work)}
if "--json" in sys.argv:
    print(json.dumps(report, indent=1))
else:
    for r in report["pet"]:
        print(f"{r['output']:17} {r['options']:16} {r['dtype']}: {r['differing']:,} of {r['samples']:,} samples differ from pydicom, max |diff| {r['max_abs_diff']:g}")
    for r in report["nifti"]:
        if "refused" in r:
            print(f"{r['file']}: refused: {r['refused']}")
        else:
            print(f"{r['file']}: {r['fields']} header fields, differing {r['differing']}, scl equal {r['scl_equal']}, "
                  f"samples bit-exact {r['samples_bit_exact']}, shape {tuple(r['shape'])}")
