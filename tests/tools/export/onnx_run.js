// Runs an ONNX model with onnxruntime-node, the ONNX runtime independent of the exporter
// (tests/tools/test_policy_export). Files are raw little-endian float32 arrays.
//
//   node onnx_run.js MODULE_DIR MODEL.onnx STATES STATE_DIM ACTIONS
//
// MODULE_DIR is the node_modules folder that holds onnxruntime-node
// (scripts/install-onnxruntime-node.sh). All states go through the model as one batch; the
// model's input is "state" and its output "action". Prints the runtime's version.
'use strict';
const fs = require('fs');
const path = require('path');

async function main() {
  const [moduleDir, modelPath, statesPath, stateDimText, actionsPath] = process.argv.slice(2);
  if (!actionsPath) throw new Error('usage: node onnx_run.js MODULE_DIR MODEL STATES DIM ACTIONS');
  const ort = require(path.join(moduleDir, 'onnxruntime-node'));
  const bytes = fs.readFileSync(statesPath);
  const states = new Float32Array(bytes.buffer, bytes.byteOffset, bytes.length / 4);
  const dim = Number(stateDimText);
  if (!(dim > 0) || states.length % dim !== 0) throw new Error('states do not fit ' + dim);
  const session = await ort.InferenceSession.create(modelPath);
  const input = new ort.Tensor('float32', states, [states.length / dim, dim]);
  const result = await session.run({state: input});
  const action = result.action.data;
  fs.writeFileSync(actionsPath, Buffer.from(action.buffer, action.byteOffset, action.byteLength));
  console.log('onnxruntime-node ' + ort.env.versions.node + ': ' + states.length / dim +
              ' states, inputs ' + session.inputNames + ', outputs ' + session.outputNames);
}

main().catch((error) => {
  console.error('onnx_run.js: ' + (error && error.stack ? error.stack : error));
  process.exit(1);
});
