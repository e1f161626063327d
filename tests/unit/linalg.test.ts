// The clean-up smoother's dense linear algebra (web/optimizer/linalg.ts) against direct products.
import { expect, it } from 'vitest';
import { cholesky, choleskySolve, inverseSPD, matmul, sandwich, transpose } from '../../web/optimizer/linalg';

/** A random symmetric positive-definite n × n matrix (B Bᵀ + n I), seeded. */
function spd(n: number, seed: number): Float64Array {
  let s = seed;
  const rand = () => ((s = (s * 1103515245 + 12345) % 2147483648) / 2147483648) - 0.5;
  const b = Float64Array.from({ length: n * n }, rand);
  const a = matmul(b, transpose(b, n, n), n, n, n);
  for (let i = 0; i < n; i++) a[i * n + i] += n;
  return a;
}

it('inverts, solves and sandwiches as the direct products do', () => {
  const n = 23;
  const a = spd(n, 7), f = spd(n, 11);
  const inv = inverseSPD(a, n);
  const id = matmul(a, inv, n, n, n);
  for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) expect(Math.abs(id[i * n + j] - (i === j ? 1 : 0))).toBeLessThan(1e-10);
  const b = Float64Array.from({ length: n * 3 }, (_, i) => Math.sin(i));
  const x = choleskySolve(cholesky(a, n), b, n, 3);
  const back = matmul(a, x, n, n, 3);
  for (let i = 0; i < b.length; i++) expect(Math.abs(back[i] - b[i])).toBeLessThan(1e-10);
  const direct = matmul(matmul(f, a, n, n, n), transpose(f, n, n), n, n, n);
  const s = sandwich(f, a, n);
  for (let i = 0; i < n * n; i++) expect(Math.abs(s[i] - direct[i])).toBeLessThan(1e-8 * Math.abs(direct[i]) + 1e-9);
});
