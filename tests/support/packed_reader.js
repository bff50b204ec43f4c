// A packed array (docs/formats.md, "Packed arrays") decoded independently of the page, for the
// browser tests: {shape, values} with float16 or float32 values as numbers.
"use strict";
const fs = require("fs");
const zlib = require("zlib");

function readPacked(file) {
  const data = fs.readFileSync(file);
  const eol = data.indexOf(10, 15);
  const h = JSON.parse(data.subarray(15, eol).toString());
  const planes = zlib.inflateSync(data.subarray(eol + 1));
  const width = h.dtype === "float16" ? 2 : 4, count = planes.length / width;
  const [n, channels] = h.shape.slice(-2);
  const bits = new Array(count);
  for (let o = 0; o < count; o += n * channels)
    for (let c = 0; c < channels; ++c)
      for (let k = 0, x = 0; k < n; ++k) {
        let d = 0;
        for (let b = 0; b < width; ++b) d += planes[b * count + o + c * n + k] * 2 ** (8 * b);
        x = (x + d) % 2 ** (8 * width);
        bits[o + k * channels + c] = x;
      }
  const half = (u) => {
    const e = (u >> 10) & 31, m = u & 1023, s = u >> 15 ? -1 : 1;
    return e === 0 ? s * m * 2 ** -24 : e === 31 ? (m ? NaN : s * Infinity) : s * (1 + m / 1024) * 2 ** (e - 15);
  };
  const view = new DataView(new ArrayBuffer(4));
  const single = (u) => { view.setUint32(0, u); return view.getFloat32(0); };
  return { shape: h.shape, values: bits.map(width === 2 ? half : single) };
}

module.exports = { readPacked };
