// laz-perf (npm, its WASM build) decoding every point of each file, best of R runs: the peer of
// laz_decode_bench. Usage: node lazperf_decode.cjs NODE_MODULES_DIR REPEATS FILE... Prints points per second
// and the FNV-1a hash of all decoded records (computed after the timed runs, over a separate decode).
const path = require('path');
const fs = require('fs');

async function main() {
  const [modules, repeatsArg, ...files] = process.argv.slice(2);
  const { createLazPerf } = require(path.join(modules, 'laz-perf'));
  const LazPerf = await createLazPerf();
  const repeats = Number(repeatsArg);
  for (const file of files) {
    const data = fs.readFileSync(file);
    const filePtr = LazPerf._malloc(data.length);
    LazPerf.HEAPU8.set(data, filePtr);
    let best = Infinity;
    let count = 0;
    const decodeAll = (visit) => {
      const laszip = new LazPerf.LASZip();
      laszip.open(filePtr, data.length);
      count = laszip.getCount();
      const length = laszip.getPointLength();
      const pointPtr = LazPerf._malloc(length);
      for (let i = 0; i < count; i++) {
        laszip.getPoint(pointPtr);
        if (visit) visit(LazPerf.HEAPU8.subarray(pointPtr, pointPtr + length));
      }
      LazPerf._free(pointPtr);
      laszip.delete();
    };
    for (let r = 0; r < repeats; r++) {
      const t = process.hrtime.bigint();
      decodeAll(null);
      best = Math.min(best, Number(process.hrtime.bigint() - t) / 1e9);
    }
    let h = 0xcbf29ce484222325n;
    const prime = 0x100000001b3n, mask = (1n << 64n) - 1n;
    decodeAll((bytes) => {
      for (const b of bytes) h = ((h ^ BigInt(b)) * prime) & mask;
    });
    LazPerf._free(filePtr);
    console.log(`laz-perf\t${file}\tthreads=1\tpoints=${count}\tdecode_s=${best.toFixed(4)}\tdecode_pts_per_s=${(count / best).toFixed(0)}\tfnv1a=${h.toString(16).padStart(16, '0')}`);
  }
}
main().catch((e) => { console.error(e); process.exit(1); });
