// Arrays as the hooks exchange them: {dtype, shape, data: TypedArray}, row-major, numpy's
// dtype names. int64 arrays hold a BigInt64Array; `at` reads any entry as a Number.

const TYPES = {
  float32: Float32Array, float64: Float64Array, int8: Int8Array, uint8: Uint8Array,
  int16: Int16Array, uint16: Uint16Array, int32: Int32Array, uint32: Uint32Array,
  int64: BigInt64Array, uint64: BigUint64Array,
};

/** The typed-array constructor of a numpy dtype name ("float32", "<f4" is not accepted). */
export function typedArrayOf(dtype) {
  const type = TYPES[dtype];
  if (!type) throw new Error(`no typed array for dtype ${dtype}`);
  return type;
}

/** An array of `dtype` and `shape` over `data` (copied into the dtype's typed array). */
export function ndarray(dtype, shape, data) {
  const Type = typedArrayOf(dtype);
  const big = Type === BigInt64Array || Type === BigUint64Array;
  let typed = data;
  if (!(data instanceof Type)) {
    typed = new Type(data.length);
    for (let i = 0; i < data.length; i++) typed[i] = big ? BigInt(data[i]) : data[i];
  }
  const size = shape.reduce((a, b) => a * b, 1);
  if (typed.length !== size) throw new Error(`${typed.length} values for shape [${shape}]`);
  return { dtype, shape: [...shape], data: typed };
}

/** Entry i (flat index) of an array as a Number (int64 included). */
export function at(array, i) {
  return Number(array.data[i]);
}

/** An array's rows of `k` numbers as a plain Float64Array copy (any dtype). */
export function float64(array) {
  const out = new Float64Array(array.data.length);
  for (let i = 0; i < out.length; i++) out[i] = Number(array.data[i]);
  return out;
}

/** An array's values as an Int32Array copy (indices of any integer dtype). */
export function int32(array) {
  const out = new Int32Array(array.data.length);
  for (let i = 0; i < out.length; i++) out[i] = Number(array.data[i]);
  return out;
}
