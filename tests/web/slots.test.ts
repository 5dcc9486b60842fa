// The order of the first downloads (web/engine/slots.ts): at most two at once, a free slot starts
// a download at once (synchronously: before any long task that follows can hold the request
// back), and a waiting download starts largest first.

import { describe, expect, it } from 'vitest';
import { DownloadSlots } from '../../web/engine/slots';

/** A download that ends when its `finish` is called. */
function pending(log: string[], name: string) {
  let finish: () => void = () => undefined;
  let fail: (error: Error) => void = () => undefined;
  const start = () => {
    log.push(name);
    return new Promise<string>((resolve, reject) => {
      finish = () => resolve(name);
      fail = reject;
    });
  };
  return { start, finish: () => finish(), fail: (error: Error) => fail(error) };
}

const settle = () => new Promise((resolve) => setTimeout(resolve, 0));

describe('DownloadSlots', () => {
  it('starts downloads synchronously while a slot is free', () => {
    const slots = new DownloadSlots(2);
    const log: string[] = [];
    slots.run(10, pending(log, 'wasm').start);
    slots.run(5, pending(log, 'follower').start);
    expect(log).toEqual(['wasm', 'follower']);
  });

  it('holds a third download until a slot frees, then starts the largest waiting one', async () => {
    const slots = new DownloadSlots(2);
    const log: string[] = [];
    const wasm = pending(log, 'wasm');
    const follower = pending(log, 'follower');
    slots.run(14, wasm.start);
    const followerDone = slots.run(2.2, follower.start);
    slots.run(1.7, pending(log, 'leader').start);
    slots.run(1.9, pending(log, 'ccm').start);
    expect(log).toEqual(['wasm', 'follower']);
    follower.finish();
    expect(await followerDone).toBe('follower');
    await settle();
    expect(log).toEqual(['wasm', 'follower', 'ccm']);
    wasm.finish();
    await settle();
    expect(log).toEqual(['wasm', 'follower', 'ccm', 'leader']);
  });

  it('frees the slot of a failed download and passes the error on', async () => {
    const slots = new DownloadSlots(1);
    const log: string[] = [];
    const broken = pending(log, 'broken');
    const failed = slots.run(3, broken.start);
    slots.run(1, pending(log, 'next').start);
    broken.fail(new Error('404'));
    await expect(failed).rejects.toThrow('404');
    await settle();
    expect(log).toEqual(['broken', 'next']);
  });

  it('turns a download that throws before its promise into a rejection', async () => {
    const slots = new DownloadSlots(1);
    await expect(slots.run(1, () => { throw new Error('no fetch'); })).rejects.toThrow('no fetch');
  });
});
