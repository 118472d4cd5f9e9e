// Runs a wasm32-wasip1 program (a test binary cargo built) under Node's
// WASI: `node wasi-run.mjs FILE.wasm ARGS...`, as cargo's runner for that
// target. The host's root is the guest's root, so the paths tests build
// from CARGO_MANIFEST_DIR resolve; the exit code is the program's.
import { readFile } from "node:fs/promises";
import { argv, env, exit } from "node:process";
import { WASI } from "node:wasi";

const [file, ...args] = argv.slice(2);
const wasi = new WASI({
    version: "preview1",
    args: [file, ...args],
    env,
    preopens: { "/": "/" },
    returnOnExit: true,
});
const module = await WebAssembly.compile(await readFile(file));
const instance = await WebAssembly.instantiate(module, wasi.getImportObject());
exit(wasi.start(instance));
