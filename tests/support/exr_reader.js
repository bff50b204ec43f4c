// Reads the EXR files `lamina render` writes (render/image.cpp: scanline RGB, 32-bit float or
// half, no compression, ZIP or ZIPS), from the OpenEXR file layout document: the magic number and
// version, attributes (name, type, size, value) up to an empty name, the offset table, then chunks
// (scanline y, size, data). ZIP data is zlib-deflated after a byte predictor (each byte stored as
// the difference to the previous plus 128) and a split of the even and odd bytes into two halves.
"use strict";
const fs = require("fs");
const zlib = require("zlib");

function readExr(file) {
  const b = fs.readFileSync(file);
  if (b.readUInt32LE(0) !== 20000630) throw new Error(`${file}: not an EXR file`);
  let at = 8;
  const cstring = () => {
    const end = b.indexOf(0, at);
    const s = b.toString("latin1", at, end);
    at = end + 1;
    return s;
  };
  const attrs = {};
  for (;;) {
    const name = cstring();
    if (!name) break;
    const type = cstring(), size = b.readInt32LE(at);
    attrs[name] = { type, value: b.subarray(at + 4, at + 4 + size) };
    at += 4 + size;
  }
  const channels = [];
  for (let c = attrs.channels.value, k = 0; c[k] !== 0;) {
    const end = c.indexOf(0, k);
    channels.push({ name: c.toString("latin1", k, end), type: c.readInt32LE(end + 1) });
    k = end + 1 + 16;
  }
  const compression = attrs.compression.value[0];
  const win = attrs.dataWindow.value;
  const x0 = win.readInt32LE(0), y0 = win.readInt32LE(4), x1 = win.readInt32LE(8), y1 = win.readInt32LE(12);
  const width = x1 - x0 + 1, height = y1 - y0 + 1;
  const lines = { 0: 1, 2: 1, 3: 16 }[compression];
  if (!lines) throw new Error(`${file}: compression ${compression} is not read here`);
  const chunks = Math.ceil(height / lines);
  const rgb = new Float32Array(width * height * 3);
  const bytesPer = (t) => (t === 1 ? 2 : 4);
  const lineBytes = channels.reduce((s, c) => s + width * bytesPer(c.type), 0);
  const half = (h) => {
    const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 31, m = h & 1023;
    if (e === 0) return s * m * Math.pow(2, -24);
    if (e === 31) return m ? NaN : s * Infinity;
    return s * (1 + m / 1024) * Math.pow(2, e - 15);
  };
  for (let k = 0; k < chunks; ++k) {
    const offset = Number(b.readBigUInt64LE(at + 8 * k));
    const y = b.readInt32LE(offset) - y0, size = b.readInt32LE(offset + 4);
    let data = b.subarray(offset + 8, offset + 8 + size);
    const n = Math.min(lines, height - y);
    if (compression !== 0 && size < n * lineBytes) {
      const t = zlib.inflateSync(data);
      for (let i = 1; i < t.length; ++i) t[i] = (t[i - 1] + t[i] - 128) & 255;
      const out = Buffer.alloc(t.length), h = (t.length + 1) >> 1;
      for (let i = 0; i < t.length; ++i) out[i] = i & 1 ? t[h + (i >> 1)] : t[i >> 1];
      data = out;
    }
    let p = 0;
    for (let l = 0; l < n; ++l)
      for (const c of channels) {
        const ch = { R: 0, G: 1, B: 2 }[c.name];
        for (let x = 0; x < width; ++x) {
          const v = c.type === 1 ? half(data.readUInt16LE(p)) : data.readFloatLE(p);
          p += bytesPer(c.type);
          if (ch !== undefined) rgb[3 * ((y + l) * width + x) + ch] = v;
        }
      }
  }
  return { width, height, rgb };
}

module.exports = { readExr };
