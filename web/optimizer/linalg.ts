// Small dense linear algebra for the clean-up smoother: row-major square and rectangular Float64Array matrices.

/** C (r × c) = A (r × k) · B (k × c). */
export function matmul(a: Float64Array, b: Float64Array, r: number, k: number, c: number, out = new Float64Array(r * c)): Float64Array {
  out.fill(0);
  for (let i = 0; i < r; i++) {
    for (let p = 0; p < k; p++) {
      const v = a[i * k + p];
      if (v === 0) continue;
      for (let j = 0; j < c; j++) out[i * c + j] += v * b[p * c + j];
    }
  }
  return out;
}

/** F P Fᵀ (n × n) for a symmetric P: F P once, then each entry of the symmetric result once. */
export function sandwich(f: Float64Array, p: Float64Array, n: number): Float64Array {
  const fp = matmul(f, p, n, n, n);
  const out = new Float64Array(n * n);
  for (let i = 0; i < n; i++) {
    for (let j = 0; j <= i; j++) {
      let s = 0;
      for (let k = 0; k < n; k++) s += fp[i * n + k] * f[j * n + k];
      out[i * n + j] = out[j * n + i] = s;
    }
  }
  return out;
}

/** Aᵀ (c × r) of A (r × c). */
export function transpose(a: Float64Array, r: number, c: number): Float64Array {
  const out = new Float64Array(r * c);
  for (let i = 0; i < r; i++) for (let j = 0; j < c; j++) out[j * r + i] = a[i * c + j];
  return out;
}

/** The lower Cholesky factor of a symmetric positive-definite n × n matrix (a small ridge is added where needed). */
export function cholesky(a: Float64Array, n: number): Float64Array {
  const l = new Float64Array(n * n);
  for (let i = 0; i < n; i++) {
    for (let j = 0; j <= i; j++) {
      let s = a[i * n + j];
      for (let k = 0; k < j; k++) s -= l[i * n + k] * l[j * n + k];
      if (i === j) l[i * n + i] = Math.sqrt(Math.max(s, 1e-12));
      else l[i * n + j] = s / l[j * n + j];
    }
  }
  return l;
}

/** X with A X = B, given A's Cholesky factor `l` (n × n); B holds m columns (n × m, row-major). Row by row, so the
 * inner loops run along contiguous memory. */
export function choleskySolve(l: Float64Array, b: Float64Array, n: number, m = 1): Float64Array {
  const x = Float64Array.from(b);
  // Forward: L Y = B.
  for (let i = 0; i < n; i++) {
    const row = i * m;
    for (let k = 0; k < i; k++) {
      const v = l[i * n + k];
      if (v === 0) continue;
      const src = k * m;
      for (let c = 0; c < m; c++) x[row + c] -= v * x[src + c];
    }
    const d = 1 / l[i * n + i];
    for (let c = 0; c < m; c++) x[row + c] *= d;
  }
  // Backward: Lᵀ X = Y.
  for (let i = n - 1; i >= 0; i--) {
    const row = i * m;
    for (let k = i + 1; k < n; k++) {
      const v = l[k * n + i];
      if (v === 0) continue;
      const src = k * m;
      for (let c = 0; c < m; c++) x[row + c] -= v * x[src + c];
    }
    const d = 1 / l[i * n + i];
    for (let c = 0; c < m; c++) x[row + c] *= d;
  }
  return x;
}

/** A⁻¹ of a symmetric positive-definite n × n matrix: L⁻¹ by forward substitution, then L⁻ᵀ L⁻¹ (each n³/3). */
export function inverseSPD(a: Float64Array, n: number): Float64Array {
  const l = cholesky(a, n);
  const li = new Float64Array(n * n); // lower triangular L⁻¹
  for (let j = 0; j < n; j++) {
    li[j * n + j] = 1 / l[j * n + j];
    for (let i = j + 1; i < n; i++) {
      let s = 0;
      for (let k = j; k < i; k++) s += l[i * n + k] * li[k * n + j];
      li[i * n + j] = -s / l[i * n + i];
    }
  }
  const inv = new Float64Array(n * n);
  for (let i = 0; i < n; i++) {
    for (let j = 0; j <= i; j++) {
      let s = 0;
      for (let k = i; k < n; k++) s += li[k * n + i] * li[k * n + j];
      inv[i * n + j] = inv[j * n + i] = s;
    }
  }
  return inv;
}
