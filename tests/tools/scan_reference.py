#!/usr/bin/python3
"""Independent reference reader for the dense-scan tests (not vdbdag code).

    scan_reference.py SCAN OUT_PREFIX [VOLUME]

NIfTI (.nii, .nii.gz, .hdr) through nibabel; NRRD (.nrrd, .nhdr) and
MetaImage (.mha, .mhd) through the small parsers below, written from the
formats' specifications. Writes OUT_PREFIX.raw (the stored samples, x
fastest, little endian, before any rescale) and OUT_PREFIX.json:
{"dims": [nx, ny, nz], "dtype": "u1|i1|u2|i2|u4|i4|f4|f8", "lps": 4x4 rows
(world_LPS = M @ [i, j, k, 1]), "slope": s, "inter": b, "components": 1|3}
(vector and RGB samples: a voxel's components together) - or {"error": "..."}
for a file nibabel refuses or a type the tests expect to be refused.
"""
import gzip
import json
import os
import re
import sys

import numpy as np

LPS_FROM_RAS = np.diag([-1.0, -1.0, 1.0, 1.0])


def nifti(path, volume):
    import nibabel as nib
    img = nib.load(path)
    hdr = img.header
    dtype = hdr.get_data_dtype()
    components = 1
    if dtype.names == ('R', 'G', 'B'):
        rgb = np.asanyarray(img.dataobj)
        data = np.stack([rgb['R'], rgb['G'], rgb['B']], axis=-1)
        components = 3
    elif dtype.kind == 'c' or dtype.names is not None:
        return {"error": "unsupported dtype %s" % dtype}, None
    else:
        data = np.asanyarray(img.dataobj.get_unscaled())
    if data.ndim == 5 and data.shape[4] == 3:
        if data.shape[3] != 1 and volume is None:
            return {"error": "4-D"}, None
        data = data[:, :, :, 0 if volume is None else volume, :]
        components = 3
    if components == 3:
        info = {"dims": list(data.shape[:3]), "components": 3}
        flat = np.ascontiguousarray(np.transpose(data, (2, 1, 0, 3))).reshape(-1)
        return finish(info, hdr, flat, (img.dataobj.slope, img.dataobj.inter))
    if data.ndim == 4:
        if volume is None:
            return {"error": "4-D"}, None
        data = data[..., volume]
    if data.ndim == 2:
        data = data[..., np.newaxis]
    return finish({"dims": list(data.shape), "components": 1}, hdr, np.asarray(data).reshape(-1, order='F'), (img.dataobj.slope, img.dataobj.inter))


def finish(info, hdr, flat, scaling=(None, None)):
    # nibabel moves scl_slope / scl_inter from a loaded header to the data
    # proxy (img.dataobj.slope / .inter): they come from there.
    slope, inter = scaling
    slope = 1.0 if slope is None or not np.isfinite(slope) else float(slope)
    inter = 0.0 if inter is None or not np.isfinite(inter) else float(inter)
    sform = int(hdr['sform_code'])
    qform = int(hdr['qform_code'])
    if sform > 0:
        affine = hdr.get_sform()
    elif qform > 0:
        affine = hdr.get_qform()
    else:
        affine = np.diag(list(hdr.get_zooms()[:3]) + [1.0])
    lps = LPS_FROM_RAS @ affine if (sform > 0 or qform > 0) else affine
    info.update({"dtype": flat.dtype.str[1:], "lps": lps.tolist(), "slope": slope, "inter": inter})
    return info, flat


NRRD_TYPES = {"uchar": "u1", "unsigned char": "u1", "uint8": "u1", "uint8_t": "u1", "signed char": "i1",
              "int8": "i1", "int8_t": "i1", "short": "i2", "int16": "i2", "int16_t": "i2", "ushort": "u2",
              "unsigned short": "u2", "uint16": "u2", "uint16_t": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "unsigned int": "u4", "uint32": "u4", "float": "f4", "double": "f8"}


def vectors(text):
    return [[float(x) for x in v.split(',')] for v in re.findall(r'\(([^)]*)\)', text)]


def nrrd(path):
    blob = open(path, 'rb').read()
    end = blob.find(b'\n\n')
    head = blob[:end if end >= 0 else len(blob)].decode('latin-1').split('\n')
    fields = {}
    for line in head[1:]:
        if line.startswith('#') or ':=' in line or ': ' not in line:
            continue
        key, value = line.split(': ', 1)
        fields[key.strip().lower()] = value.strip()
    dims = [int(x) for x in fields['sizes'].split()]
    components = 1
    if len(dims) == 4:
        components, dims = dims[0], dims[1:]
    dtype = NRRD_TYPES[fields['type']]
    endian = '>' if fields.get('endian', 'little') == 'big' else '<'
    if 'data file' in fields:
        payload = open(os.path.join(os.path.dirname(path), fields['data file']), 'rb').read()
    else:
        payload = blob[end + 2:]
    if fields['encoding'] in ('gzip', 'gz'):
        payload = gzip.decompress(payload)
    count = dims[0] * dims[1] * dims[2] * components
    skip = int(fields.get('byte skip', '0'))
    size = np.dtype(dtype).itemsize
    if skip == -1:
        payload = payload[len(payload) - count * size:]
    else:
        payload = payload[skip:]
    data = np.frombuffer(payload[:count * size], dtype=endian + dtype).astype('<' + dtype)
    m = np.eye(4)
    if 'space directions' in fields:
        dirs = [v for v in re.split(r'\s+(?![^(]*\))', fields['space directions'].strip()) if v != 'none']
        for a, v in enumerate(dirs):
            m[:3, a] = vectors(v)[0]
    elif 'spacings' in fields:
        for a, s in enumerate(fields['spacings'].split()):
            m[a, a] = float(s)
    if 'space origin' in fields:
        m[:3, 3] = vectors(fields['space origin'])[0]
    space = fields.get('space', '').lower()
    if space in ('right-anterior-superior', 'ras'):
        m = LPS_FROM_RAS @ m
    return {"dims": dims, "dtype": dtype, "lps": m.tolist(), "slope": 1.0, "inter": 0.0, "components": components}, data


MET_TYPES = {"MET_UCHAR": "u1", "MET_CHAR": "i1", "MET_USHORT": "u2", "MET_SHORT": "i2", "MET_UINT": "u4",
             "MET_INT": "i4", "MET_FLOAT": "f4", "MET_DOUBLE": "f8"}


def metaimage(path):
    blob = open(path, 'rb').read()
    fields, pos = {}, 0
    while True:
        nl = blob.index(b'\n', pos)
        key, value = blob[pos:nl].decode('latin-1').split('=', 1)
        fields[key.strip().lower()] = value.strip()
        pos = nl + 1
        if key.strip().lower() == 'elementdatafile':
            break
    dims = [int(x) for x in fields['dimsize'].split()]
    components = int(fields.get('elementnumberofchannels', '1'))
    dtype = MET_TYPES[fields['elementtype']]
    endian = '>' if fields.get('binarydatabyteordermsb', fields.get('elementbyteordermsb', 'False')) == 'True' else '<'
    name = fields['elementdatafile']
    payload = blob[pos:] if name == 'LOCAL' else open(os.path.join(os.path.dirname(path), name), 'rb').read()
    count = dims[0] * dims[1] * dims[2] * components
    data = np.frombuffer(payload[:count * np.dtype(dtype).itemsize], dtype=endian + dtype).astype('<' + dtype)
    spacing = [float(x) for x in fields.get('elementspacing', '1 1 1').split()]
    matrix = [float(x) for x in fields.get('transformmatrix', '1 0 0 0 1 0 0 0 1').split()]
    m = np.eye(4)
    for a in range(3):
        m[:3, a] = np.array(matrix[3 * a:3 * a + 3]) * spacing[a]
    m[:3, 3] = [float(x) for x in fields.get('offset', '0 0 0').split()]
    return {"dims": dims, "dtype": dtype, "lps": m.tolist(), "slope": 1.0, "inter": 0.0, "components": components}, data


def main():
    path, out = sys.argv[1], sys.argv[2]
    volume = int(sys.argv[3]) if len(sys.argv) > 3 else None
    lower = path.lower()
    try:
        if lower.endswith(('.nii', '.nii.gz', '.hdr')):
            info, data = nifti(path, volume)
        elif lower.endswith(('.nrrd', '.nhdr')):
            info, data = nrrd(path)
        elif lower.endswith(('.mha', '.mhd')):
            info, data = metaimage(path)
        else:
            raise ValueError("unknown format")
    except Exception as e:  # the test decides whether a refusal was expected
        info, data = {"error": str(e)}, None
    if data is not None:
        flat = np.asarray(data).reshape(-1)
        with open(out + '.raw', 'wb') as f:
            f.write(flat.astype(flat.dtype.newbyteorder('<')).tobytes())
    with open(out + '.json', 'w') as f:
        json.dump(info, f)


if __name__ == '__main__':
    main()
