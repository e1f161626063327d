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

/** x with A x = b, given A's Cholesky factor `l` (n × n); b may hold m columns (n × m). */
export function choleskySolve(l: Float64Array, b: Float64Array, n: number, m = 1): Float64Array {
  const x = Float64Array.from(b);
  for (let col = 0; col < m; col++) {
    for (let i = 0; i < n; i++) {
      let s = x[i * m + col];
      for (let k = 0; k < i; k++) s -= l[i * n + k] * x[k * m + col];
      x[i * m + col] = s / l[i * n + i];
    }
    for (let i = n - 1; i >= 0; i--) {
      let s = x[i * m + col];
      for (let k = i + 1; k < n; k++) s -= l[k * n + i] * x[k * m + col];
      x[i * m + col] = s / l[i * n + i];
    }
  }
  return x;
}

/** A⁻¹ of a symmetric positive-definite n × n matrix. */
export function inverseSPD(a: Float64Array, n: number): Float64Array {
  const identity = new Float64Array(n * n);
  for (let i = 0; i < n; i++) identity[i * n + i] = 1;
  const inv = choleskySolve(cholesky(a, n), identity, n, n);
  // Symmetrise against rounding.
  for (let i = 0; i < n; i++) for (let j = 0; j < i; j++) inv[i * n + j] = inv[j * n + i] = (inv[i * n + j] + inv[j * n + i]) / 2;
  return inv;
}
