#!/usr/bin/env python3
# Writes the bad-input corpus beside this script: one directory per
# input kind; cli/badinput_corpus_test.cpp runs each file through rayaudit.
# The files are committed; this script only documents how the binary ones
# were made (rerun it after changing one). Expected messages: expected.tsv.
import os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))

def put(kind, name, data):
    d = os.path.join(HERE, kind)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), 'wb') as f:
        f.write(data)

def put_dir(kind, name):
    # A directory where a file is expected (git needs a file inside it).
    d = os.path.join(HERE, kind, name)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, 'README'), 'w') as f:
        f.write('A directory given where a file is expected.\n')

TRI = 'v 0 0 0\nv 1 0 0\nv 0 1 0\n'

# ---- OBJ ----
put('obj', 'v_two_values.obj', 'v 1 2\n')
put('obj', 'v_nan.obj', TRI + 'v nan 0 0\nf 1 2 3\n')
put('obj', 'v_inf.obj', 'v 0 0 0\nv 1 0 0\nv inf 1 0\nf 1 2 3\n')
put('obj', 'v_word.obj', 'v 0 zero 0\n')
put('obj', 'face_index_zero.obj', TRI + 'f 0 1 2\n')
put('obj', 'face_past_end.obj', TRI + 'f 1 2 9\n')
put('obj', 'face_two_vertices.obj', TRI + 'f 1 2\n')
put('obj', 'face_malformed_index.obj', TRI + 'f 1 2 x\n')
put('obj', 'face_relative_too_far.obj', TRI + 'f -1 -2 -9\n')
put('obj', 'face_forward_reference.obj', 'f 1 2 3\n' + TRI)
put('obj', 'face_index_overflow.obj', TRI + 'f 1 2 99999999999999999999\n')
put('obj', 'vn_two_values.obj', 'vn 1 0\n')
put('obj', 'vt_no_values.obj', 'vt\n')
put('obj', 's_bad.obj', TRI + 's maybe\nf 1 2 3\n')
put('obj', 'utf16.obj', '\ufeffv 0 0 0\n'.encode('utf-16-le'))
put('obj', 'binary_nul.obj', b'v 0 0 0\n\x00\x01\x02\xff\xfe\n')
put_dir('obj', 'is_a_directory.obj')

# ---- MTL (each referenced by an OBJ the test writes) ----
put('mtl', 'kd_two_values.mtl', 'newmtl a\nKd 1 0\n')
put('mtl', 'kd_words.mtl', 'newmtl a\nKd red green blue\n')
put('mtl', 'ns_no_value.mtl', 'newmtl a\nNs\n')
put('mtl', 'd_no_value.mtl', 'newmtl a\nd\n')
put('mtl', 'illum_huge.mtl', 'newmtl a\nillum 1e300\n')
put('mtl', 'd_above_one.mtl', 'newmtl a\nd 1.5\n')
put('mtl', 'd_negative.mtl', 'newmtl a\nd -0.25\n')
put('mtl', 'tr_above_one.mtl', 'newmtl a\nTr 2\n')
put('mtl', 'ni_nan.mtl', 'newmtl a\nillum 7\nNi nan\n')
put('mtl', 'ni_zero_refracting.mtl', 'newmtl a\nillum 7\nd 0.1\nNi 0\n')
put('mtl', 'illum_fraction.mtl', 'newmtl a\nillum 2.5\n')
put('mtl', 'map_without_file.mtl', 'newmtl a\nmap_Kd -s 1 1 1\n')
put('mtl', 'map_option_without_value.mtl', 'newmtl a\nmap_Kd -bm\n')
put('mtl', 'ks_overflow.mtl', 'newmtl a\nKs 1e999 0 0\n')

# ---- PLY ascii ----
def ply_header(fmt, nv, nf, vtype='float', itype='int', ctype='uchar', extra=''):
    return ('ply\nformat %s 1.0\nelement vertex %d\nproperty %s x\nproperty %s y\nproperty %s z\n%s'
            'element face %d\nproperty list %s %s vertex_indices\nend_header\n'
            % (fmt, nv, vtype, vtype, vtype, extra, nf, ctype, itype))
ASCII_V = '0 0 0\n1 0 0\n0 1 0\n'
put('ply', 'no_magic.ply', 'plx\nformat ascii 1.0\nend_header\n')
put('ply', 'no_end_header.ply', 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n')
put('ply', 'unknown_format.ply', 'ply\nformat ascii2 1.0\nend_header\n')
put('ply', 'no_format.ply', 'ply\nelement vertex 0\nend_header\n')
put('ply', 'count_2pow31.ply', ply_header('ascii', 2147483648, 0) + ASCII_V)
put('ply', 'count_more_than_file.ply', ply_header('ascii', 1000000000, 1) + ASCII_V + '3 0 1 2\n')
put('ply', 'unknown_type.ply', 'ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\nend_header\n0\n')
put('ply', 'vertex_without_z.ply', 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n')
put('ply', 'property_before_element.ply', 'ply\nformat ascii 1.0\nproperty float x\nend_header\n')
put('ply', 'index_out_of_range.ply', ply_header('ascii', 3, 1) + ASCII_V + '3 0 1 7\n')
put('ply', 'nan_coordinate.ply', ply_header('ascii', 3, 1) + '0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'face_two_vertices.ply', ply_header('ascii', 3, 1) + ASCII_V + '2 0 1\n')
put('ply', 'extra_values.ply', ply_header('ascii', 3, 1) + '0 0 0 9\n1 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'malformed_value.ply', ply_header('ascii', 3, 1) + '0 0 abc\n1 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'list_count_negative.ply', ply_header('ascii', 3, 1) + ASCII_V + '-3 0 1 2\n')
put('ply', 'unknown_header_line.ply', 'ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n')

# ---- PLY binary ----
def bin_v(*pts, fmt='<fff'):
    return b''.join(struct.pack(fmt, *p) for p in pts)
V3 = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
put('ply', 'bin_truncated.ply', ply_header('binary_little_endian', 3, 1).encode() + bin_v(*V3)[:20])
put('ply', 'bin_index_out_of_range.ply', ply_header('binary_little_endian', 3, 1).encode() + bin_v(*V3)
    + struct.pack('<Biii', 3, 0, 1, 70000))
put('ply', 'bin_nan_index.ply', ply_header('binary_little_endian', 3, 1, itype='float').encode() + bin_v(*V3)
    + struct.pack('<Bfff', 3, 0, 1, float('nan')))
put('ply', 'bin_fraction_index.ply', ply_header('binary_little_endian', 3, 1, itype='float').encode() + bin_v(*V3)
    + struct.pack('<Bfff', 3, 0, 1.5, 2))
put('ply', 'bin_nan_coordinate.ply', ply_header('binary_little_endian', 3, 1).encode()
    + bin_v((0, 0, 0), (float('nan'), 0, 0), (0, 1, 0)) + struct.pack('<Biii', 3, 0, 1, 2))
put('ply', 'bin_list_count_huge.ply', ply_header('binary_little_endian', 3, 1, ctype='uint').encode() + bin_v(*V3)
    + struct.pack('<Iiii', 4000000000, 0, 1, 2))
put('ply', 'bin_face_two_vertices.ply', ply_header('binary_little_endian', 3, 1).encode() + bin_v(*V3)
    + struct.pack('<Bii', 2, 0, 1))
put('ply', 'bin_count_more_than_file.ply', ply_header('binary_little_endian', 100000000, 1).encode() + bin_v(*V3)
    + struct.pack('<Biii', 3, 0, 1, 2))
put('ply', 'bin_big_endian_truncated.ply', ply_header('binary_big_endian', 3, 1).encode() + bin_v(*V3, fmt='>fff')
    + struct.pack('>Bi', 3, 0))

# ---- OFF ----
put('off', 'zzz_magic.off', 'ZZZOFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', '4off_magic.off', '4OFF\n3 1 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2\n')
put('off', 'no_magic.off', '3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'counts_negative.off', 'OFF\n-3 1 0\n')
put('off', 'counts_more_than_file.off', 'OFF\n1000000000 1 0\n0 0 0\n')
put('off', 'counts_2pow31.off', 'OFF\n2147483649 1 0\n0 0 0\n')
put('off', 'vertex_two_values.off', 'OFF\n3 1 0\n0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'face_index_out_of_range.off', 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n')
put('off', 'face_two_vertices.off', 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n')
put('off', 'nan_vertex.off', 'OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'malformed_number.off', 'OFF\n3 1 0\n0 0 0\n1 0 0x\n0 1 0\n3 0 1 2\n')

# ---- scene JSON ----
put('scene', 'syntax_error.json', '{"width": 8,\n "height": }\n')
put('scene', 'truncated.json', '{"width": 8,\n "height": 8\n')
put('scene', 'trailing_garbage.json', '{"width": 8}\nx\n')
put('scene', 'ior_zero.json', '{"objects": [{"sphere": {}, "material": {"transmit": 0.5, "ior": 0}}]}\n')
put('scene', 'ior_negative.json', '{"objects": [{"sphere": {}, "material": {"ior": -1.5}}]}\n')
put('scene', 'transmit_above_one.json', '{"objects": [{"sphere": {}, "material": {"transmit": 1.5}}]}\n')
put('scene', 'filter_negative.json', '{"objects": [{"sphere": {}, "material": {"filter": -0.1}}]}\n')
put('scene', 'duplicate_key.json', '{"width": 8,\n "height": 8,\n "width": 9}\n')
put('scene', 'overflow_number.json', '{"notes": "1e400",\n "width": 1e400}\n')
put('scene', 'unknown_key.json', '{"width": 8,\n "heigth": 8}\n')
put('scene', 'width_zero.json', '{"width": 0}\n')
put('scene', 'width_string.json', '{"width": "eight"}\n')
put('scene', 'not_an_object.json', '[1, 2]\n')
put('scene', 'empty.json', '')
put('scene', 'camera_number.json', '{"camera": 5}\n')
put('scene', 'mesh_missing.json', '{"objects": [{"mesh": "no-such-mesh.obj"}]}\n')
put('scene', 'mesh_is_directory.json', '{"objects": [{"mesh": "."}]}\n')
put('scene', 'utf16.json', '\ufeff{"width": 8}\n'.encode('utf-16-le'))
put('scene', 'deep_nesting.json', '[' * 100000)
put('scene', 'sphere_negative_radius.json', '{"objects": [{"sphere": {"center": [0, 0, 0], "radius": -1}}]}\n')
put_dir('scene', 'is_a_directory.json')

# ---- cases CSV ----
HEAD = 'ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n'
ROW = '0.25,0.25,-1,0,0,1,0,0,0,1,0,0,0,1,0\n'
put('csv', 'empty.csv', '')
put('csv', 'missing_column.csv', HEAD.replace('oz,', '') + ROW)
put('csv', 'utf16.csv', ('\ufeff' + HEAD + ROW).encode('utf-16-le'))
put('csv', 'duplicate_column.csv', HEAD.strip() + ',ox\n' + ROW.strip() + ',9\n')
put('csv', 'not_a_number.csv', HEAD + ROW.replace('0.25,0.25', '0.25,abc', 1))
put('csv', 'field_count.csv', HEAD + '0,0,0\n')
put('csv', 'overflow.csv', HEAD + ROW.replace('0.25,0.25', '1e400,0.25', 1))
put('csv', 'binary_nul.csv', b'\x00\x01\x02\n\xff\xfe')
put('csv', 'second_row_bad.csv', HEAD + ROW + ROW.replace('-1', '-1x'))
put_dir('csv', 'is_a_directory.csv')

# ---- POV tolerance JSON (compare loads it before rendering) ----
put('tolerance', 'syntax_error.json', '{"notes": "x",\n "pixels": [}\n')
put('tolerance', 'duplicate_key.json', '{"notes": "a",\n "notes": "b"}\n')
put('tolerance', 'not_an_object.json', '[]\n')
put('tolerance', 'width_string.json', '{"width": "320"}\n')
put('tolerance', 'pixel_not_object.json', '{"pixels": [5]}\n')
put('tolerance', 'pixel_x_string.json', '{"pixels": [{"x": "1", "y": 2, "levels": 3, "cause": "c"}]}\n')
put('tolerance', 'levels_out_of_range.json', '{"pixels": [{"x": 1, "y": 2, "levels": 300, "cause": "c"}]}\n')
put('tolerance', 'pixel_without_cause.json', '{"pixels": [{"x": 1, "y": 2, "levels": 3}]}\n')
put('tolerance', 'unknown_key.json', '{"pixel": []}\n')
put('tolerance', 'max_levels_out_of_range.json', '{"max_levels_16": 99}\n')

# ---- golden manifest (copied to ROOT/golden/manifest.json by the test) ----
put('golden', 'syntax_error.json', '{"goldens": [\n{]\n')
put('golden', 'not_an_object.json', '[]\n')
put('golden', 'goldens_not_array.json', '{"goldens": 5}\n')
put('golden', 'entry_not_object.json', '{"goldens": [7]}\n')
put('golden', 'entry_without_name.json', '{"goldens": [{"scene": "s.json"}]}\n')
put('golden', 'duplicate_key.json', '{"goldens": [],\n "goldens": []}\n')
put('golden', 'width_string.json', '{"goldens": [{"name": "a", "scene": "scenes/a.json", "image": "golden/a.png", '
    '"width": "8", "height": 8, "inputs_hash": "x"}]}\n')
put('golden', 'listed_twice.json', '{"goldens": [' + ','.join(
    ['{"name": "a", "scene": "scenes/a.json", "image": "golden/a.png", "width": 8, "height": 8, "inputs_hash": "x"}'] * 2)
    + ']}\n')
# An entry read strictly: unknown keys, sizes that are not integers.
GOLDEN_A = '"name": "a", "scene": "scenes/a.json", "image": "golden/a.png", "height": 8, "inputs_hash": "x"'
put('golden', 'unknown_key.json', '{"goldens": [{' + GOLDEN_A + ', "width": 8,\n "widht": 8}]}\n')
put('golden', 'width_fraction.json', '{"goldens": [{' + GOLDEN_A + ', "width": 1.5}]}\n')
put('golden', 'width_2p63.json', '{"goldens": [{' + GOLDEN_A + ', "width": 9223372036854775808}]}\n')

# ---- textures (referenced by a scene the test writes) ----
def png(w, h, data, color=2, depth=8, crc_ok=True):
    def chunk(t, d):
        c = zlib.crc32(t + d) & 0xffffffff
        return struct.pack('>I', len(d)) + t + d + struct.pack('>I', c if crc_ok else c ^ 1)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, depth, color, 0, 0, 0))
            + chunk(b'IDAT', data) + chunk(b'IEND', b''))
good = png(2, 2, zlib.compress(b'\x00' + b'\x80' * 6 + b'\x00' + b'\x40' * 6))
put('texture', 'huge_header.png', png(20000, 20000, zlib.compress(b'\x00' * 8)))
put('texture', 'header_larger_than_file.png', png(10000, 10000, zlib.compress(b'\x00' * 8)))
put('texture', 'million_side.png', png(1000000, 1000000, zlib.compress(b'\x00' * 8)))
put('texture', 'truncated.png', good[:len(good) - 20])
put('texture', 'bad_crc.png', png(2, 2, zlib.compress(b'\x00' + b'\x80' * 6 + b'\x00' + b'\x40' * 6), crc_ok=False))
put('texture', 'not_an_image.png', 'this is not a PNG\n')
put('texture', 'zero_bytes.png', b'')
put('texture', 'idat_garbage.png', png(4, 4, b'\x01\x02\x03garbage'))
put('texture', 'not_an_exr.exr', 'v/1\x01 not really an EXR\n')
put('texture', 'zero_width.png', png(0, 4, zlib.compress(b'\x00' * 4)))
put_dir('texture', 'is_a_directory.png')

# ---- across kinds: values out of range, NaN, bytes that are not UTF-8, paths that loop ----
PH = 'ply\nformat ascii 1.0\nelement vertex 3\n'
put('ply', 'duplicate_property.ply', PH + 'property float x\nproperty float x\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n')
put('ply', 'list_count_float.ply', PH + 'property float x\nproperty float y\nproperty float z\nelement face 1\nproperty list float int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'nul_in_value.ply', PH + 'property float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 \x00\n0 1 0\n')
put('off', 'binary_off.off', 'OFF BINARY\n3 1 0\n')
put('scene', 'mesh_is_ply.json', '{"objects": [{"mesh": "../ply/extra_values.ply"}]}\n')
put('scene', 'invalid_utf8.json', b'{"objects": [{"mesh": "\xff\xfe.obj"}]}\n')
HD = 'ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\n'
put('csv', 'nan_value.csv', HD + 'nan,0.2,1,0,0,-1,0,0,0,1,0,0,0,1,0\n')
put('csv', 'inf_value.csv', HD + '0.2,0.2,1,0,0,-inf,0,0,0,1,0,0,0,1,0\n')
put('csv', 'long_number.csv', HD + '1' * 5000 + ',0.2,1,0,0,-1,0,0,0,1,0,0,0,1,0\n')
put('tolerance', 'pixel_x_negative.json', '{"width": 8, "height": 8, "pixels": [{"x": -1, "y": 0, "levels": 1, "cause": "c"}]}\n')
put('tolerance', 'pixel_outside_width.json', '{"width": 8, "height": 8, "pixels": [{"x": 8, "y": 0, "levels": 1, "cause": "c"}]}\n')
put('tolerance', 'width_zero.json', '{"width": 0, "pixels": []}\n')
GE = '"inputs": {}, "inputs_hash": "fnv1a64:0", '
put('golden', 'name_traversal.json', '{"goldens": [{' + GE + '"name": "../../evil", "scene": "scenes/a.json", "image": "golden/a.png", "width": 8, "height": 8}]}\n')
put('golden', 'image_absolute.json', '{"goldens": [{' + GE + '"name": "a", "scene": "scenes/a.json", "image": "/etc/hostname", "width": 8, "height": 8}]}\n')
put('golden', 'width_negative.json', '{"goldens": [{' + GE + '"name": "a", "scene": "scenes/a.json", "image": "golden/a.png", "width": -8, "height": 8}]}\n')
put('golden', 'size_huge.json', '{"goldens": [{' + GE + '"name": "a", "scene": "scenes/a.json", "image": "golden/a.png", "width": 100000, "height": 100000}]}\n')
put('golden', 'bits_12.json', '{"goldens": [{' + GE + '"name": "a", "scene": "scenes/a.json", "image": "golden/a.png", "width": 8, "height": 8, "bits": 12}]}\n')
put('mtl', 'map_kd_symlink_loop.mtl', 'newmtl a\nmap_Kd ../texture/symlink_loop.png\n')
put('mtl', 'map_kd_directory.mtl', 'newmtl a\nmap_Kd ../texture/is_a_directory.png\n')
# A symlink to itself (git keeps it): opening it fails with ELOOP.
loop = os.path.join(HERE, 'texture', 'symlink_loop.png')
if not os.path.islink(loop):
    os.symlink('symlink_loop.png', loop)

# -2^63 as a relative index (its negation overflowed,
# and the index read before the first vertex).
V3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
put("obj", "face_index_neg_2p63.obj", V3 + "f 1 2 -9223372036854775808\n")
put("obj", "vt_index_neg_2p63.obj", V3 + "vt 0 0\nf 1/1 2/1 3/-9223372036854775808\n")
put("obj", "vn_index_neg_2p63.obj", V3 + "vn 0 0 1\nf 1//1 2//1 3//-9223372036854775808\n")
# texture/jpeg_truncated.jpg: the first 1000 bytes of `oiiotool --pattern
# noise 128x128 3 -d uint8 -o n.jpg` (18 KB): read "successfully" with the
# rest grey unless the reader's error state is checked (not regenerated here).
put('texture', 'gif_absurd_size.gif', b'GIF89a\xff\xff\xff\xff\x00\x00\x00,\x00\x00\x00\x00\xff\xff\xff\xff\x00\x02\x02\x44\x01\x00;')
put('scene', 'newline_in_key.json', '{"objects": [], "a\\nb": 1}\n')
FACE1 = 'element face 1\nproperty list uchar int vertex_indices\nend_header\n'
put('ply', 'version_2.ply', 'ply\nformat ascii 2.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n' + FACE1 + '0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'char_value_300.ply', 'ply\nformat ascii 1.0\nelement vertex 3\nproperty char x\nproperty char y\nproperty char z\n' + FACE1 + '0 0 0\n300 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'list_as_coordinate.ply', 'ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\nproperty float z\nend_header\n1 5 0 0\n')
put('tolerance', 'pixel_listed_twice.json', '{"width": 8, "height": 8, "pixels": [{"x": 1, "y": 1, "levels": 1, "cause": "x"}, {"x": 1, "y": 1, "levels": 2, "cause": "y"}]}\n')
put('scene', 'camera_1e308.json', '{"camera": {"position": [1e308, 0, 5]}, "objects": [{"sphere": {"radius": 1}}]}\n')
put('scene', 'radius_denormal.json', '{"objects": [{"sphere": {"radius": 1e-320}}]}\n')
put('scene', 'adc_bailout_negative.json', '{"adc_bailout": -1, "objects": [{"sphere": {"radius": 1}}]}\n')
put('scene', 'mesh_is_json.json', '{"objects": [{"mesh": "mesh_is_json.json"}]}\n')

# What the magic or the counts promise; header
# errors at their header line; CR-only line ends counted as line ends.
put('off', 'noff_without_normals.off', 'NOFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'coff_without_colours.off', 'COFF\n3 1 0\n0 0 0 1 1 1 1\n1 0 0\n0 1 0 1 1 1 1\n3 0 1 2\n')
put('off', 'cnoff_colour_only.off', 'CNOFF\n3 1 0\n0 0 0 0 0 1 1 1 1\n1 0 0 1 1 1\n0 1 0 0 0 1 1 1 1\n3 0 1 2\n')
put('off', 'fewer_faces.off', 'OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'fewer_vertices.off', 'OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n')
put('off', 'counts_without_edges.off', 'OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'cr_only_line_ends.off', 'OFF\r3 1 0\r0 0 0\r1 0 0\r0 1 0\r3 0 1 x\r')
put('ply', 'face_without_vertex_indices.ply', 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int idx\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'cr_only_line_ends.ply', 'ply\rformat ascii 1.0\relement vertex 3\rproperty float x\rproperty float y\rproperty float z\rend_header\r0 0 0\r1 0 0\r0 q 0\r')
# `l` and `p` are not rendered, but their indices are checked like a face's.
put('obj', 'l_index_past_end.obj', TRI + 'f 1 2 3\nl 1 2 9\n')
put('obj', 'l_index_zero.obj', TRI + 'l 0 1\nf 1 2 3\n')
put('obj', 'p_relative_too_far.obj', TRI + 'f 1 2 3\np -4\n')
put('obj', 'l_texture_past_end.obj', TRI + 'vt 0 0\nf 1 2 3\nl 1/1 2/2\n')
put('obj', 'l_one_vertex.obj', TRI + 'f 1 2 3\nl 1\n')
# CR-only line ends (classic Mac OS) are line ends: errors at the right line.
put('scene', 'cr_only_line_ends.json', '{\r"width": 8,\r"height": 8,\r"objects": [}\r')
put('csv', 'cr_only_line_ends.csv', 'ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\r0,0,0,0,0,1,0,0,1,1,0,1,0,1,1\r0,0,x,0,0,1,0,0,1,1,0,1,0,1,1\r')
put('csv', 'mixed_line_ends.csv', 'ox,oy,oz,dx,dy,dz,ax,ay,az,bx,by,bz,cx,cy,cz\r\n0,0,0,0,0,1,0,0,1,1,0,1,0,1,1\r0,0,0,0,0,1,0,0,1,1,0,1,0,1,1\n0,0,0,0,0,1,0,0,1,1,0,1,0,1\r\n')
# The settings a golden records are checked as render checks its flags, at their line.
GS = '{\n  "goldens": [\n    {\n      ' + GE + '"name": "a", "scene": "scenes/a.json", "image": "golden/a.png", "width": 8, "height": 8,\n      "settings": {\n        "triangle_method": "moller",\n        "spp": %s\n      }\n    }\n  ]\n}\n'
put('golden', 'spp_2.json', GS % '2')
put('golden', 'spp_huge.json', GS % '1000000')
put('golden', 'triangle_method_unknown.json', GS.replace('"moller"', '"mollerr"') % '1')
# Textures OIIO's readers accepted silently, and files that are no image:
# refused in our words (via a scene, map_Kd and bump).
put('texture', 'png_without_iend.png', good[:good.rindex(b'IEND') - 4])
put('texture', 'ppm_maxval_0.ppm', b'P6\n2 2\n0\n' + b'\x00' * 12)
put('texture', 'p3_maxval_0.ppm', 'P3\n# a comment\n2 2\n0\n0 0 0 0 0 0 0 0 0 0 0 0\n')
put('texture', 'obj_as_texture.png', TRI + 'f 1 2 3\n')
put('texture', 'random_bytes.bin', bytes((i * 7919 + 13) % 251 for i in range(2000)))
put('mtl', 'map_kd_names_itself.mtl', 'newmtl a\nmap_Kd map_kd_names_itself.mtl\n')
put('mtl', 'bump_names_an_obj.mtl', 'newmtl a\nbump ../obj/v_word.obj\n')
put('mtl', 'map_bump_empty_file.mtl', 'newmtl a\nmap_bump ../texture/zero_bytes.png\n')
put('mtl', 'map_kd_png_without_iend.mtl', 'newmtl a\nKd 1 1 1\nmap_Kd ../texture/png_without_iend.png\n')
put('mtl', 'bump_ppm_maxval_0.mtl', 'newmtl a\nbump -bm 2 ../texture/ppm_maxval_0.ppm\n')
put('golden', 'deep_nesting.json', '{"goldens": ' + '[' * 100000 + '\n')
# PLY/OFF data the header does not
# declare, an element twice, a float beyond float, counts beyond three.
PLY3 = 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n' + FACE1
put('ply', 'element_twice.ply', 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n' + FACE1 + '0 0 0\n1 0 0\n0 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'float_1e39.ply', PLY3 + '1e39 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('ply', 'trailing_line.ply', PLY3 + '0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n1 2 3\n')
put('ply', 'bin_trailing_bytes.ply', PLY3.replace('ascii', 'binary_little_endian').encode() + struct.pack('<9f', 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack('<B3i', 3, 0, 1, 2) + b'garbage')
put('ply', 'bin_uint_index_2p32.ply', PLY3.replace('ascii', 'binary_little_endian').replace('uchar int', 'uchar uint').encode() + struct.pack('<9f', 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack('<B3I', 3, 0, 1, 2**32 - 1))
put('ply', 'format_after_element.ply', 'ply\nelement vertex 3\nformat ascii 1.0\nend_header\n')
put('ply', 'two_index_lists.ply', 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nproperty list uchar int vertex_index\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 3 0 1 2\n')
put('off', 'trailing_face.off', 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n')
put('off', 'vertex_extra_values.off', 'OFF\n3 1 0\n0 0 0 9 9\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'four_counts.off', 'OFF\n3 1 0 7\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put('off', 'face_word_after_indices.off', 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 xyz\n')
# Sizes OIIO's GIF reader allocated in
# open(), PNM/PFM values out of range, non-finite texels, a GIF without image.
put('texture', 'gif_16384_in_35_bytes.gif', b'GIF89a\x00\x40\x00\x40\x80\x00\x00\x00\x00\x00\xff\xff\xff,\x00\x00\x00\x00\x00\x40\x00\x40\x00\x02\x02\x44\x01\x00;')
put('texture', 'gif_without_image.gif', b'GIF89a\x04\x00\x04\x00\x00\x00\x00;')
put('texture', 'ppm_maxval_65536.ppm', b'P6\n2 2\n65536\n' + b'\x00' * 24)
put('texture', 'ppm_maxval_negative.ppm', b'P6\n2 2\n-1\n' + b'\x00' * 24)
put('texture', 'p3_sample_above_maxval.ppm', 'P3\n2 2\n255\n0 0 0\n999 0 0 0 0 0 0 0 0\n')
put('texture', 'p2_negative_sample.pgm', 'P2\n2 2\n15\n-5 0 0 0\n')
put('texture', 'pbm_bit_2.pbm', 'P1\n2 2\n0 2 0 1\n')
put('texture', 'pfm_scale_0.pfm', b'PF\n2 2\n0\n' + struct.pack('<f', 1.0) * 12)
put('texture', 'pfm_nan_texel.pfm', b'PF\n2 2\n-1.0\n' + struct.pack('<f', 0.5) * 3 + struct.pack('<f', float('nan')) * 9)
# The file's own number quoted; a directory named as such.
put('tolerance', 'pixel_x_2p63.json', '{"width": 8, "height": 8, "pixels": [{"x": 9223372036854775808, "y": 1, "levels": 1, "cause": "c"}]}\n')
put_dir('tolerance', 'is_a_directory.json')
# PNM data shorter than the header promises (OIIO: "unreadable or
# unsupported image", or the rest read as black).
put('texture', 'p6_truncated.ppm', b'P6\n2 2\n255\n' + b'\x00' * 7)
put('texture', 'p3_truncated.ppm', 'P3\n2 2\n255\n1 2 3\n')
put('tolerance', 'width_not_the_images.json', '{"width": 16, "height": 16, "pixels": []}\n')
