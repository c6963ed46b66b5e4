// A second Draco decoder for python/tests/test_precomputed_multires.py: the npm package draco3d
// (Google's Emscripten build, scripts/setup.sh installs it under python/tests/node/), independent
// of Debian's libdraco that writes the fragments. Reads the .drc files named on the command line
// and prints, per file, {"positions": [x, y, z, ...], "faces": [a, b, c, ...]} as one JSON line.
'use strict';
const fs = require('fs');
const draco3d = require('draco3d');

draco3d.createDecoderModule({}).then((m) => {
  for (const file of process.argv.slice(2)) {
    const bytes = new Int8Array(fs.readFileSync(file));
    const buffer = new m.DecoderBuffer();
    buffer.Init(bytes, bytes.length);
    const decoder = new m.Decoder();
    if (decoder.GetEncodedGeometryType(buffer) !== m.TRIANGULAR_MESH) throw new Error(file + ': not a mesh');
    const mesh = new m.Mesh();
    const status = decoder.DecodeBufferToMesh(buffer, mesh);
    if (!status.ok()) throw new Error(file + ': ' + status.error_msg());
    const id = decoder.GetAttributeId(mesh, m.POSITION);
    const attribute = decoder.GetAttribute(mesh, id);
    const values = new m.DracoInt32Array();
    decoder.GetAttributeInt32ForAllPoints(mesh, attribute, values);
    const positions = [];
    for (let i = 0; i < values.size(); ++i) positions.push(values.GetValue(i));
    const faces = [];
    const face = new m.DracoInt32Array();
    for (let f = 0; f < mesh.num_faces(); ++f) {
      decoder.GetFaceFromMesh(mesh, f, face);
      faces.push(face.GetValue(0), face.GetValue(1), face.GetValue(2));
    }
    process.stdout.write(JSON.stringify({positions, faces}) + '\n');
    [values, face, mesh, decoder, buffer].forEach((o) => m.destroy(o));
  }
});
