// The neural policies: one ONNX InferenceSession per model, stepped once per frame.
//
// I/O contract (docs/features.md): inputs `input` [B, 660] (the leader's [B, 704]), `temperature` [1], `noise` [B, C·D]
// uniform in (0, 1); outputs `output` [B, 323], `intention` [B, 90] (only models with an intention
// predictor), `code` [B, C]. Everything here is allocated once: callers write into `input`, call
// run(), and read `result`, so stepping at 30 Hz creates no garbage of ours.

import { loaderTypeProblem, ort } from './ort';
import type { Manifest, ModelEntry, PolicyResult, StepPolicy } from './types';
import { DuetError } from '../ui/errors';
import { createUniform, fillUniform } from './random';
import { INPUT_SIZES, INTENTION_SIZE, OUTPUT_SIZE } from '../mirror/features';

/** The input width of a model's role (the leader's input adds his control and hands plan). */
function inputSize(entry: ModelEntry): number {
  return INPUT_SIZES[entry.role] ?? INPUT_SIZES.follower;
}

type Session = Awaited<ReturnType<typeof ort.InferenceSession.create>>;
type Tensor = InstanceType<typeof ort.Tensor>;

/** Buffers and tensors for one batch size, created on first use and kept. */
interface Batch {
  size: number;
  input: Float32Array;
  noise: Float32Array;
  feeds: Record<string, Tensor>;
  result: PolicyResult;
}

export class Policy implements StepPolicy {
  /** Write the [660] (leader: [704]) input features here before run(). */
  readonly input: Float32Array;
  /** Filled by run(); the same object and arrays every call. */
  readonly result: PolicyResult;
  /** Milliseconds spent in session runs since this policy was made (the step's network part). */
  networkMs = 0;

  private readonly temperature = new Float32Array(1);
  private readonly temperatureTensor: Tensor;
  private readonly batches = new Map<number, Batch>();
  private readonly draws = new Map<number, Batch>();
  private readonly fetches: string[];
  private readonly uniform: () => number;
  private readonly single: Batch;

  constructor(
    /** Manifest key: 'follower', 'follower_ccm', 'leader'. */
    readonly name: string,
    readonly entry: ModelEntry,
    private readonly session: Session,
    seed: number,
  ) {
    this.uniform = createUniform(seed);
    this.temperatureTensor = new ort.Tensor('float32', this.temperature, [1]);
    // Fetch only what we read; `code` is for evaluation.
    this.fetches = entry.intention ? ['output', 'intention'] : ['output'];
    this.single = this.batch(1);
    this.input = this.single.input;
    this.result = this.single.result;
  }

  get hasIntention(): boolean {
    return this.entry.intention;
  }

  /** One step for one character: reads `input`, fills `result`. */
  run(temperature: number): Promise<PolicyResult> {
    return this.runBatch(1, temperature);
  }

  /** The [k × 660] input block for a batched run (e.g. k ghost samples); write rows here. */
  batchInput(k: number): Float32Array {
    return this.batch(k).input;
  }

  /** k samples at once, each with its own noise: reads batchInput(k), returns [k × ...] results. */
  runBatch(k: number, temperature: number): Promise<PolicyResult> {
    return this.runWith(this.batch(k), temperature);
  }

  /**
   * k samples of `input` at once, each with its own noise: the encoders run once, the sampling and
   * the decoder k times (the guards' and the count's choices). Returns output [k × 323] and the
   * intention [90], one: it does not depend on the noise.
   */
  runDraws(k: number, temperature: number): Promise<PolicyResult> {
    return this.runWith(this.drawsOf(k), temperature);
  }

  /** One session run on a batch's feeds with fresh noise, its results copied into the batch's arrays. */
  private async runWith(batch: Batch, temperature: number): Promise<PolicyResult> {
    this.temperature[0] = temperature;
    fillUniform(batch.noise, this.uniform);
    const started = performance.now();
    const outputs = await this.session.run(batch.feeds, this.fetches);
    this.networkMs += performance.now() - started;
    copyOut(outputs.output, batch.result.output);
    if (batch.result.intention) copyOut(outputs.intention, batch.result.intention);
    return batch.result;
  }

  private drawsOf(k: number): Batch {
    let batch = this.draws.get(k);
    if (!batch) {
      const noiseSize = this.entry.channels * this.entry.classes;
      const noise = new Float32Array(k * noiseSize);
      batch = {
        size: k,
        input: this.input,
        noise,
        feeds: { input: this.single.feeds.input, temperature: this.temperatureTensor, noise: new ort.Tensor('float32', noise, [k, noiseSize]) },
        result: { output: new Float32Array(k * OUTPUT_SIZE), intention: this.entry.intention ? new Float32Array(INTENTION_SIZE) : null },
      };
      this.draws.set(k, batch);
    }
    return batch;
  }

  private batch(k: number): Batch {
    let batch = this.batches.get(k);
    if (!batch) {
      const noiseSize = this.entry.channels * this.entry.classes;
      const width = inputSize(this.entry);
      const input = new Float32Array(k * width);
      const noise = new Float32Array(k * noiseSize);
      batch = {
        size: k,
        input,
        noise,
        feeds: {
          input: new ort.Tensor('float32', input, [k, width]),
          temperature: this.temperatureTensor,
          noise: new ort.Tensor('float32', noise, [k, noiseSize]),
        },
        result: {
          output: new Float32Array(k * OUTPUT_SIZE),
          intention: this.entry.intention ? new Float32Array(k * INTENTION_SIZE) : null,
        },
      };
      this.batches.set(k, batch);
    }
    return batch;
  }
}

function copyOut(tensor: Tensor | undefined, into: Float32Array): void {
  if (!tensor || tensor.data.length !== into.length) {
    throw new DuetError('Model output has the wrong size', `expected ${into.length} numbers, got ${tensor?.data.length}`);
  }
  into.set(tensor.data as Float32Array);
  // CPU tensors are plain arrays, but dispose() is the API's way to free a tensor, whatever its location.
  tensor.dispose();
}

/**
 * How every model's session is made (tests/e2e/runtime.test.mjs makes its sessions the same way).
 * With two threads, onnxruntime's second thread would spin for work after each run by default,
 * holding a core that the page's drawing and the next step need (and a phone's battery): told not
 * to, it waits asleep. The outputs are the same; on the 2-core machine the 2-thread step took
 * 1.58 ms against 1.67 ms (mean of 4 alternating `npm run bench -- --threads 2` runs each).
 */
export const SESSION_OPTIONS = {
  executionProviders: ['wasm'],
  graphOptimizationLevel: 'all' as const,
  extra: { session: { intra_op: { allow_spinning: '0' } } },
};

/** Create the session for one model from its bytes (see fetchModelBytes in manifest.ts). */
export async function createPolicy(manifest: Manifest, name: string, bytes: Uint8Array, seed: number): Promise<Policy> {
  const entry = manifest.models[name];
  if (!entry) throw new DuetError('Model not found', `"${name}" is not in manifest.json`);
  let session: Session;
  try {
    session = await ort.InferenceSession.create(bytes, SESSION_OPTIONS);
  } catch (error) {
    // A host that sends onnxruntime's loader with another type than JavaScript stops every model.
    const served = await loaderTypeProblem();
    if (served) throw new DuetError('The host sends a script with the wrong type', served);
    // onnxruntime's own message can be empty ("ERROR_MESSAGE: "): say what it means in any case.
    const detail = String((error as Error)?.message ?? error).trim();
    throw new DuetError(
      'A model file is corrupt',
      `models/${entry.file} is not a readable ONNX model (damaged or half downloaded; a reload fetches it again)` +
        (detail ? `. onnxruntime: ${detail}` : ''),
    );
  }
  checkSession(name, entry, session);
  await warmUp(session, entry, warmDraws(manifest, entry));
  return new Policy(name, entry, session, seed);
}

/**
 * The draws of one input a model runs at: one step, the samples of its dancer's choice on the
 * count (every step), and those of its upright guard (simulation.ts). The guard acts in well under
 * 1 % of steps, so its first draws can come minutes into a dance; warmed up here, that step does
 * not wait for new buffers. (The WebAssembly memory can still take one growth step later:
 * tests/e2e/soak.test.mjs.)
 */
function warmDraws(manifest: Manifest, entry: ModelEntry): number[] {
  const guard = entry.role === 'leader' ? manifest.leaderGuard : manifest.guard;
  if (!guard || guard.samples < 2) return [1];
  const count = manifest.onCount && manifest.onCount.samples >= 2 ? [manifest.onCount.samples] : [];
  return [...new Set([1, guard.samples, ...count])];
}

/**
 * One run per batch size on neutral inputs right after the session is created. A session's first
 * run at a size is much slower than the next ones (onnxruntime allocates and plans its buffers
 * then): done here, it overlaps with the other downloads instead of delaying the first dancing
 * frame. Tensors of its own, so the policy's noise stream (and so the dance for a seed) is untouched.
 */
async function warmUp(session: Session, entry: ModelEntry, draws: number[]): Promise<void> {
  const width = inputSize(entry);
  const noise = entry.channels * entry.classes;
  for (const k of draws) {
    const outputs = await session.run({
      input: new ort.Tensor('float32', new Float32Array(width), [1, width]),
      temperature: new ort.Tensor('float32', new Float32Array([1]), [1]),
      noise: new ort.Tensor('float32', new Float32Array(k * noise).fill(0.5), [k, noise]),
    }, entry.intention ? ['output', 'intention'] : ['output']);
    for (const tensor of Object.values(outputs)) tensor.dispose();
  }
}

/** The ONNX graph must have the inputs and outputs of the contract, with matching widths. */
function checkSession(name: string, entry: ModelEntry, session: Session): void {
  const bad = (detail: string) => new DuetError('A model does not match this page', `${name}: ${detail}`);
  const widths: Record<string, number> = { input: inputSize(entry), noise: entry.channels * entry.classes };
  for (const input of ['input', 'temperature', 'noise']) {
    if (!session.inputNames.includes(input)) throw bad(`no input named "${input}"`);
  }
  for (const meta of session.inputMetadata) {
    const width = widths[meta.name];
    if (width === undefined || !meta.isTensor) continue;
    const last = meta.shape[meta.shape.length - 1];
    if (typeof last === 'number' && last !== width) throw bad(`input "${meta.name}" is ${last} wide, expected ${width}`);
  }
  if (!session.outputNames.includes('output')) throw bad('no output named "output"');
  if (entry.intention && !session.outputNames.includes('intention')) throw bad('manifest says intention, the model has no "intention" output');
}
