// laminad's JSON-RPC over the console's WebSocket (/ws): the same methods and notifications as
// its Unix socket (docs/api.md). Reconnects with a growing pause after the link drops; calls
// made while it is down fail at once (the UI says so) rather than being sent late.

export interface RpcErrorBody {
  code: number;
  message: string;
  data?: unknown;
}

export class RpcError extends Error {
  constructor(readonly code: number, message: string) {
    super(message);
  }
}

type Listener = (params: any) => void;
type LinkListener = (up: boolean, why: string) => void;

export class Rpc {
  private ws?: WebSocket;
  private nextId = 1;
  private pending = new Map<number, { resolve: (v: any) => void; reject: (e: Error) => void }>();
  private listeners = new Map<string, Listener[]>();
  private linkListeners: LinkListener[] = [];
  private retryMs = 500;
  private stopped = false;

  connect(): void {
    this.stopped = false;
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    const ws = new WebSocket(`${scheme}://${location.host}/ws`);
    this.ws = ws;
    ws.onopen = async () => {
      this.retryMs = 500;
      this.emitLink(true, "connected");
      try {
        await this.call("server.subscribe");
      } catch (e) {
        this.emitLink(false, `subscribe failed: ${(e as Error).message}`);
      }
    };
    ws.onmessage = (event) => this.onMessage(String(event.data));
    ws.onclose = (event) => {
      for (const { reject } of this.pending.values()) reject(new RpcError(-32099, "the connection to laminad dropped"));
      this.pending.clear();
      this.emitLink(false, event.reason || `closed (${event.code})`);
      if (this.stopped) return;
      setTimeout(() => this.connect(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, 8000);
    };
  }

  close(): void {
    this.stopped = true;
    this.ws?.close();
  }

  call<T = any>(method: string, params: object = {}): Promise<T> {
    const ws = this.ws;
    if (!ws || ws.readyState !== WebSocket.OPEN)
      return Promise.reject(new RpcError(-32099, "not connected to laminad"));
    const id = this.nextId++;
    ws.send(JSON.stringify({ jsonrpc: "2.0", id, method, params }));
    return new Promise<T>((resolve, reject) => this.pending.set(id, { resolve, reject }));
  }

  on(method: string, listener: Listener): void {
    this.listeners.set(method, [...(this.listeners.get(method) ?? []), listener]);
  }

  onLink(listener: LinkListener): void {
    this.linkListeners.push(listener);
  }

  private emitLink(up: boolean, why: string): void {
    for (const l of this.linkListeners) l(up, why);
  }

  private onMessage(text: string): void {
    let message: any;
    try {
      message = JSON.parse(text);
    } catch {
      return;
    }
    if (message.method) {
      for (const l of this.listeners.get(message.method) ?? []) l(message.params);
      return;
    }
    const waiting = this.pending.get(message.id);
    if (!waiting) return;
    this.pending.delete(message.id);
    if (message.error) waiting.reject(new RpcError(message.error.code, message.error.message));
    else waiting.resolve(message.result);
  }
}
