"""Scans go back as they came, checked by readers that are not vdbdag's:
nibabel for NIfTI, pydicom for DICOM, and the NRRD / MetaImage parsers of
tests/tools/scan_reference.py (written from the formats' specifications).

- every NIfTI file of ../shared/data/medical/nifti (3-D) goes through
  encode then decode -o .nii.gz with every header field equal under nibabel
  and the samples bit-exact; a file with a header extension, an intent and
  NIfTI-2 ones made here with nibabel;
- a rescaled DICOM series (a CT with intercept -1000 and Bits Stored 12,
  made here with pydicom; the PET of ../shared when present) decoded to
  NRRD and MetaImage holds pydicom's rescaled values; --stored-values holds
  the stored integers and the rescale as key/value pairs;
- diff pairs a scan with its own decoded file and treats float32 NIfTI
  transforms as equal to the NRRD's.
Uses the command line (VDBDAG_EXECUTABLE) only."""
import glob
import json
import os
import subprocess
import sys

import numpy as np
import pytest

nib = pytest.importorskip("nibabel")
pydicom = pytest.importorskip("pydicom")

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tools"))
import scan_reference  # noqa: E402  (the NRRD / MetaImage reference parsers)

EXE = os.environ.get("VDBDAG_EXECUTABLE", os.path.join(os.path.dirname(__file__), "..", "..", "build", "vdbdag"))
SHARED = os.environ.get("VDBDAG_SHARED_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))
NIFTI = os.path.join(SHARED, "medical", "nifti")


def run(*args, ok=(0,)):
    r = subprocess.run([EXE, *args], capture_output=True, text=True)
    assert r.returncode in ok, f"{args}: exit {r.returncode}\n{r.stdout}\n{r.stderr}"
    return r


def round_trip(src, work, name, ext=".nii.gz", extra=()):
    enc = os.path.join(work, name + ".ssvdag")
    out = os.path.join(work, name + "_back" + ext)
    run("encode", src, "-o", enc, "-q", "--force")
    r = run("decode", enc, "-o", out, "--force", *extra)
    return enc, out, r


def header_differences(a, b):
    """Every field of nibabel's header view, compared exactly (arrays
    element by element; NaN equals NaN)."""
    out = []
    for key in a.keys():
        va, vb = np.asarray(a[key]), np.asarray(b[key])
        if va.shape != vb.shape:
            out.append(f"{key}: {va} vs {vb}")
            continue
        if va.dtype.kind == "f":
            same = np.array_equal(va, vb, equal_nan=True)
        else:
            same = np.array_equal(va, vb)
        if not same:
            out.append(f"{key}: {va} vs {vb}")
    return out


def scaling(img):
    """scl_slope / scl_inter as stored (nibabel moves them from the loaded
    header to the data proxy)."""
    return (float(img.dataobj.slope), float(img.dataobj.inter))


def nifti_files():
    if not os.path.isdir(NIFTI):
        return []
    files = []
    for f in sorted(glob.glob(os.path.join(NIFTI, "*.nii*"))):
        img = nib.load(f)
        if img.header.get_data_dtype().kind == "c" or len(img.shape) > 3:
            continue  # complex is refused; 4-D is checked below
        files.append(os.path.basename(f))
    return files


@pytest.mark.parametrize("name", nifti_files() or [pytest.param("none", marks=pytest.mark.skip(reason="no ../shared/data/medical/nifti"))])
def test_every_nifti_header_field_comes_back(name, tmp_path):
    src = os.path.join(NIFTI, name)
    _, out, _ = round_trip(src, str(tmp_path), name.split(".")[0])
    a, b = nib.load(src), nib.load(out)
    assert header_differences(a.header, b.header) == []
    assert scaling(a) == scaling(b)
    assert np.allclose(a.get_qform(), b.get_qform(), atol=1e-5) and np.allclose(a.get_sform(), b.get_sform(), atol=1e-5)
    sa, sb = np.asanyarray(a.dataobj.get_unscaled()), np.asanyarray(b.dataobj.get_unscaled())
    assert sa.dtype == sb.dtype and sa.tobytes() == sb.tobytes()


def made_nifti(path, version, dtype=np.int16, endian="<"):
    rng = np.random.default_rng(3)
    data = rng.integers(0, 3000, size=(13, 11, 7)).astype(dtype)
    affine = np.array([[-0.9, 0.05, 0, 90.5], [0.02, 1.1, 0, -126.25], [0, 0, 2.5, -72], [0, 0, 0, 1]])
    cls = nib.Nifti1Image if version == 1 else nib.Nifti2Image
    img = cls(data, affine, cls.header_class(endianness=endian))
    h = img.header
    h.set_sform(affine, code=4)  # MNI152
    h.set_qform(np.diag([-0.9, 1.1, 2.5, 1]) @ np.eye(4) + np.array([[0, 0, 0, 90.5], [0, 0, 0, -126.25], [0, 0, 0, -72], [0, 0, 0, 0]]), code=1)
    h["descrip"] = b"made for vdbdag's tests"
    h["aux_file"] = b"lut.txt"
    h.set_intent("t test", (12.0,), name="tstat")
    h.set_xyzt_units("mm", "sec")
    h["cal_min"], h["cal_max"] = 10, 2500
    h["slice_code"], h["slice_start"], h["slice_end"], h["slice_duration"] = 1, 0, 6, 0.07
    h.set_dim_info(freq=0, phase=1, slice=2)
    h["toffset"] = 1.5
    h.extensions.append(nib.nifti1.Nifti1Extension(6, b"a comment that travels with the file"))
    nib.save(img, path)


@pytest.mark.parametrize("version,endian", [(1, "<"), (2, "<"), (1, ">")])
def test_made_nifti_with_extension_and_intent(version, endian, tmp_path):
    src = str(tmp_path / f"made{version}.nii.gz")
    made_nifti(src, version, endian=endian)
    _, out, _ = round_trip(src, str(tmp_path), f"made{version}")
    a, b = nib.load(src), nib.load(out)
    assert type(a.header) is type(b.header)
    assert header_differences(a.header, b.header) == [] and scaling(a) == scaling(b)
    assert [(e.get_code(), e.get_content()) for e in a.header.extensions] == [(e.get_code(), e.get_content()) for e in b.header.extensions]
    sa, sb = np.asanyarray(a.dataobj), np.asanyarray(b.dataobj)  # values: a big-endian file comes back little-endian
    assert sa.dtype.newbyteorder("=") == sb.dtype.newbyteorder("=") and np.array_equal(sa, sb)


def write_ct_series(folder, intercept=-1000.0, slope=1.0, bits_stored=12):
    """A small CT series (uint16 samples, Bits Stored 12) with a rescale."""
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, generate_uid
    os.makedirs(folder, exist_ok=True)
    rng = np.random.default_rng(7)
    series, study, frame = generate_uid(), generate_uid(), generate_uid()
    stored = []
    for k in range(5):
        px = rng.integers(0, 2 ** bits_stored, size=(12, 16)).astype(np.uint16)
        stored.append(px)
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.SOPClassUID, ds.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
        ds.Modality, ds.PatientName, ds.PatientID = "CT", "Test^Rescale", "0"
        ds.StudyInstanceUID, ds.SeriesInstanceUID, ds.FrameOfReferenceUID = study, series, frame
        ds.SeriesNumber, ds.InstanceNumber = 1, k + 1
        ds.ImagePositionPatient = [-10.0, -20.0, 30.0 + 1.25 * k]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.PixelSpacing = [0.75, 0.5]
        ds.SliceThickness = 1.25
        ds.Rows, ds.Columns = px.shape
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, bits_stored, bits_stored - 1, 0
        ds.RescaleIntercept, ds.RescaleSlope = intercept, slope
        ds.PixelData = px.tobytes()
        ds.is_little_endian, ds.is_implicit_VR = True, False
        ds.save_as(os.path.join(folder, f"slice{k:02d}.dcm"), write_like_original=False)
    return np.stack(stored).astype(np.float64) * slope + intercept  # z, y, x


def read_reference(path):
    """The samples (z, y, x) and header of a NRRD or MetaImage file through
    the reference parsers, and the header's raw text."""
    reader = scan_reference.nrrd if path.endswith((".nrrd", ".nhdr")) else scan_reference.metaimage
    info, flat = reader(path)
    assert "error" not in info, info
    nx, ny, nz = info["dims"]
    samples = np.asarray(flat).reshape(nz, ny, nx)
    with open(path, "rb") as f:
        head = f.read(4096).split(b"\n\n")[0].decode("latin-1")
    return samples, info, head


@pytest.mark.parametrize("ext", [".nrrd", ".mha", ".nhdr", ".mhd"])
def test_rescaled_ct_decodes_to_hounsfield_units(ext, tmp_path):
    expected = write_ct_series(str(tmp_path / "ct"))
    _, out, r = round_trip(str(tmp_path / "ct"), str(tmp_path), "ct", ext)
    samples, info, _ = read_reference(out)
    assert np.array_equal(samples.astype(np.float64), expected)
    assert samples.dtype == np.int16  # -1000..3095 HU: the 12 stored bits say int16 suffices
    assert "note:" in r.stderr and "--stored-values" in r.stderr


@pytest.mark.parametrize("ext", [".nrrd", ".mha"])
def test_stored_values_keep_the_rescale_as_key_values(ext, tmp_path):
    expected = write_ct_series(str(tmp_path / "ct"))
    _, out, _ = round_trip(str(tmp_path / "ct"), str(tmp_path), "ct", ext, extra=("--stored-values",))
    samples, info, head = read_reference(out)
    assert np.array_equal(samples.astype(np.float64) - 1000.0, expected)
    key = "rescale_intercept:=-1000" if ext == ".nrrd" else "RescaleIntercept = -1000"
    assert key in head


def test_rescaled_ct_to_nifti_keeps_stored_samples_and_scl(tmp_path):
    expected = write_ct_series(str(tmp_path / "ct"))
    _, out, _ = round_trip(str(tmp_path / "ct"), str(tmp_path), "ct", ".nii.gz")
    img = nib.load(out)
    values = np.asanyarray(img.dataobj).transpose(2, 1, 0)  # nibabel applies scl_slope / scl_inter
    assert np.array_equal(values, expected)


def pet_series():
    folder = os.path.join(SHARED, "medical", "dicom", "rsna_2", "PET")
    return folder if os.path.isdir(folder) else None


@pytest.mark.skipif(pet_series() is None, reason="no ../shared/data/medical/dicom/rsna_2/PET")
@pytest.mark.parametrize("ext", [".nrrd", ".mha"])
def test_pet_decodes_to_its_rescaled_values(ext, tmp_path):
    folder = pet_series()
    slices = [pydicom.dcmread(f) for f in sorted(glob.glob(os.path.join(folder, "*")))]
    slices = [d for d in slices if "PixelData" in d]
    normal = np.cross(np.array(slices[0].ImageOrientationPatient[:3], float), np.array(slices[0].ImageOrientationPatient[3:], float))
    slices.sort(key=lambda d: float(np.dot(normal, np.array(d.ImagePositionPatient, float))))
    expected = np.stack([d.pixel_array.astype(np.float64) * float(d.RescaleSlope) + float(d.RescaleIntercept) for d in slices])
    _, out, _ = round_trip(folder, str(tmp_path), "pet", ext)
    samples, info, _ = read_reference(out)
    assert samples.dtype == np.float32
    assert np.array_equal(samples, expected.astype(np.float32))


@pytest.mark.skipif(not os.path.exists(os.path.join(SHARED, "dense", "FLAIR.nrrd")), reason="no ../shared/data/dense/FLAIR.nrrd")
def test_diff_pairs_what_the_user_means(tmp_path):
    nrrd, nii = os.path.join(SHARED, "dense", "FLAIR.nrrd"), os.path.join(NIFTI, "FLAIR.nii.gz")
    r = run("diff", nrrd, nii, "--json")
    report = json.loads(r.stdout)
    assert report["identical"] and report["header_differences"] == []
    enc, back, _ = round_trip(nrrd, str(tmp_path), "flair", ".nrrd")
    r = run("diff", enc, back, "--json")
    report = json.loads(r.stdout)
    assert report["identical"] and len(report["grids"]) == 1
    assert report["grids"][0]["voxels"]["value_differs"] == 0 and report["grids"][0]["voxels"]["only_in_a"] == 0
    run("diff", enc, back, "--pair", "name", ok=(1,))  # 'flair' vs 'flair_back': no namesake


@pytest.mark.skipif(not os.path.exists(os.path.join(NIFTI, "mpld_asl.nii.gz")), reason="no ../shared/data/medical/nifti/mpld_asl.nii.gz")
def test_4d_series_comes_back_as_one_file(tmp_path):
    src = os.path.join(NIFTI, "mpld_asl.nii.gz")
    enc, out, _ = round_trip(src, str(tmp_path), "asl")
    a, b = nib.load(src), nib.load(out)
    assert b.shape == a.shape == (64, 64, 24, 25)
    assert header_differences(a.header, b.header) == [] and scaling(a) == scaling(b)
    assert np.asanyarray(a.dataobj.get_unscaled()).tobytes() == np.asanyarray(b.dataobj.get_unscaled()).tobytes()
    one = str(tmp_path / "t7.nii.gz")
    run("decode", enc, "-o", one, "--grid", "mpld_asl_t7")  # --grid still picks one volume
    assert np.array_equal(np.asanyarray(nib.load(one).dataobj), np.asanyarray(a.dataobj)[..., 7])


def test_rgb_vector_on_the_4th_axis_is_one_vector_grid(tmp_path):
    rng = np.random.default_rng(11)
    data = rng.integers(0, 256, size=(9, 7, 5, 3)).astype(np.uint8)
    img = nib.Nifti1Image(data, np.diag([1.5, 1.5, 2.0, 1.0]))
    img.header.set_intent("rgb vector")
    src = str(tmp_path / "rgbvec.nii.gz")
    nib.save(img, src)
    enc, out, _ = round_trip(src, str(tmp_path), "rgbvec")
    info = json.loads(run("info", enc, "--json").stdout)
    grids = info["grids"]
    assert len(grids) == 1 and grids[0]["value_type"].startswith("vec3")
    a, b = nib.load(src), nib.load(out)
    assert header_differences(a.header, b.header) == []
    assert np.asanyarray(a.dataobj).tobytes() == np.asanyarray(b.dataobj).tobytes()


def header_lines(path):
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    end = head.find(b"\n\n")
    return head[:end if end >= 0 else len(head)].decode("latin-1").split("\n")


def test_nrrd_fields_and_key_values_come_back(tmp_path):
    rng = np.random.default_rng(5)
    samples = rng.integers(-500, 500, size=(4, 5, 6)).astype("<i2")  # z, y, x
    src = tmp_path / "fields.nrrd"
    head = ("NRRD0004\n# a comment\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 6 5 4\n"
            "space directions: (0.5,0,0) (0,0.5,0) (0,0,1.25)\nkinds: domain domain domain\nendian: little\nencoding: raw\n"
            "space origin: (1,2,3)\ncontent: a test volume\nspace units: \"mm\" \"mm\" \"mm\"\n"
            "measurement frame: (1,0,0) (0,1,0) (0,0,1)\nthicknesses: 0.5 0.5 1.25\n"
            "DICOM_0008_0060_Modality:=CT\nsubject id:=42\n\n")
    src.write_bytes(head.encode() + samples.tobytes())
    _, out, _ = round_trip(str(src), str(tmp_path), "fields", ".nrrd")
    lines = set(header_lines(out))
    for line in ["content: a test volume", "space units: \"mm\" \"mm\" \"mm\"", "measurement frame: (1,0,0) (0,1,0) (0,0,1)",
                 "thicknesses: 0.5 0.5 1.25", "DICOM_0008_0060_Modality:=CT", "subject id:=42"]:
        assert line in lines, line
    back, info, _ = read_reference(out)
    assert np.array_equal(back, samples)


def test_metaimage_tags_come_back(tmp_path):
    rng = np.random.default_rng(6)
    samples = rng.integers(0, 255, size=(3, 4, 5)).astype(np.uint8)
    src = tmp_path / "tags.mha"
    head = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\n"
            "TransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 0 0 0\nAnatomicalOrientation = RAI\nElementSpacing = 1 1 2\n"
            "Modality = MET_MOD_CT\nElementSize = 1 1 2.5\nDimSize = 5 4 3\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n")
    src.write_bytes(head.encode() + samples.tobytes())
    _, out, _ = round_trip(str(src), str(tmp_path), "tags", ".mha")
    with open(out, "rb") as f:
        text = f.read(4096).decode("latin-1")
    assert "Modality = MET_MOD_CT\n" in text and "ElementSize = 1 1 2.5\n" in text
    back, info, _ = read_reference(out)
    assert np.array_equal(back, samples)


def test_dicom_tags_travel_and_patient_tags_can_be_dropped(tmp_path):
    write_ct_series(str(tmp_path / "ct"))
    first = pydicom.dcmread(str(tmp_path / "ct" / "slice00.dcm"))
    kept, dropped = str(tmp_path / "kept.ssvdag"), str(tmp_path / "dropped.ssvdag")
    run("encode", str(tmp_path / "ct"), "-o", kept, "-q")
    run("encode", str(tmp_path / "ct"), "-o", dropped, "-q", "--drop-patient-tags")
    meta = json.loads(run("info", kept, "--json").stdout)["grids"][0]["metadata"]
    assert meta["dicom_PatientName"]["value"] == str(first.PatientName)
    assert meta["dicom_SeriesInstanceUID"]["value"] == first.SeriesInstanceUID
    assert meta["dicom_BitsStored"]["value"] == "12" and float(meta["dicom_RescaleIntercept"]["value"]) == float(first.RescaleIntercept)
    meta = json.loads(run("info", dropped, "--json").stdout)["grids"][0]["metadata"]
    assert "dicom_PatientName" not in meta and "dicom_PatientID" not in meta
    assert meta["dicom_SeriesInstanceUID"]["value"] == first.SeriesInstanceUID


def test_what_another_format_cannot_carry_is_said_in_one_note(tmp_path):
    src = str(tmp_path / "made.nii.gz")
    made_nifti(src, 1)
    _, out, r = round_trip(src, str(tmp_path), "made", ".nrrd")
    notes = [line for line in r.stderr.splitlines() if "note:" in line]
    assert len(notes) == 1 and "NIfTI header fields (nifti_*) have no place in made_back.nrrd" in notes[0], r.stderr
    _, out, r = round_trip(src, str(tmp_path), "made", ".nii.gz")
    assert "note:" not in r.stderr, r.stderr  # everything went back


@pytest.mark.parametrize("unit,nifti_code", [("mm", 2), ("m", 1), ("um", 3)])
def test_units_map_between_nifti_and_nrrd(unit, nifti_code, tmp_path):
    # NIfTI xyzt_units -> NRRD space units
    data = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6)
    img = nib.Nifti1Image(data, np.diag([0.5, 0.5, 2.0, 1.0]))
    img.header.set_xyzt_units({"mm": "mm", "m": "meter", "um": "micron"}[unit], "sec")
    src = str(tmp_path / "units.nii.gz")
    nib.save(img, src)
    _, out, _ = round_trip(src, str(tmp_path), "units", ".nrrd")
    assert f'space units: "{unit}" "{unit}" "{unit}"' in header_lines(out)
    # NRRD space units -> NIfTI xyzt_units
    nrrd = tmp_path / "units_src.nrrd"
    head = ("NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 6 5 4\n"
            "space directions: (0.5,0,0) (0,0.5,0) (0,0,2)\nendian: little\nencoding: raw\nspace origin: (0,0,0)\n"
            f'space units: "{unit}" "{unit}" "{unit}"\n\n')
    nrrd.write_bytes(head.encode() + data.astype("<i2").tobytes())
    _, out, _ = round_trip(str(nrrd), str(tmp_path), "units_src", ".nii.gz")
    assert int(nib.load(out).header["xyzt_units"]) & 7 == nifti_code


def test_nrrd_series_comes_back_as_one_4d_file(tmp_path):
    rng = np.random.default_rng(9)
    samples = rng.integers(-300, 300, size=(3, 4, 5, 6)).astype("<i2")  # t, z, y, x
    src = tmp_path / "series.nrrd"
    head = ("NRRD0004\ntype: short\ndimension: 4\nspace: left-posterior-superior\nsizes: 6 5 4 3\n"
            "space directions: (0.5,0,0) (0,0.5,0) (0,0,1.5) none\nkinds: domain domain domain list\nendian: little\nencoding: raw\n"
            "space origin: (1,2,3)\nlabels: \"x\" \"y\" \"z\" \"t\"\nsubject:=7\n\n")
    src.write_bytes(head.encode() + samples.tobytes())
    enc = str(tmp_path / "series.ssvdag")
    run("encode", str(src), "-o", enc, "-q")
    grids = json.loads(run("info", enc, "--json").stdout)["grids"]
    assert sorted(g["name"] for g in grids) == ["series_t0", "series_t1", "series_t2"]
    # Back as one 4-D NRRD: the same header fields and the same bytes.
    out = str(tmp_path / "series_back.nrrd")
    run("decode", enc, "-o", out)
    lines = header_lines(out)
    for line in ["sizes: 6 5 4 3", "kinds: domain domain domain list", 'labels: "x" "y" "z" "t"', "subject:=7"]:
        assert line in lines, (line, lines)
    assert any(line.startswith("space directions:") and line.endswith(" none") for line in lines)
    with open(out, "rb") as f:
        blob = f.read()
    assert blob[blob.index(b"\n\n") + 2:] == samples.tobytes()
    # One volume: a 3-D file (the 4-entry labels left out), volume 1's samples.
    one = str(tmp_path / "t1.nrrd")
    run("decode", enc, "-o", one, "--grid", "series_t1")
    back, info, _ = read_reference(one)
    assert np.array_equal(back, samples[1]) and not any(l.startswith("labels:") for l in header_lines(one))
    # As NIfTI: one 4-D file, nibabel's (x, y, z, t).
    nii = str(tmp_path / "series.nii.gz")
    run("decode", enc, "-o", nii)
    assert np.array_equal(np.asanyarray(nib.load(nii).dataobj), samples.transpose(3, 2, 1, 0))
