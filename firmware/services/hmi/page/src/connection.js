// The WebSocket to the controller, opened again (with a fresh snapshot) whenever it drops.
export function connect(path, onMessage, onState) {
  let socket = null;
  const open = () => {
    const scheme = window.location.protocol === 'https:' ? 'wss:' : 'ws:';
    socket = new WebSocket(`${scheme}//${window.location.host}${path}`);
    onState('connecting…');
    socket.onopen = () => onState('live');
    socket.onmessage = (event) => {
      let message;
      try {
        message = JSON.parse(event.data);
      } catch (error) {
        console.error('not JSON from the server', error);
        return;
      }
      onMessage(message);
    };
    socket.onclose = () => {
      onState('disconnected: the job has ended or the controller stopped; retrying');
      setTimeout(open, 200);  // a restarted display is back within a second
    };
  };
  open();
  return {
    send(message) {
      if (socket && socket.readyState === WebSocket.OPEN) {
        socket.send(JSON.stringify(message));
      }
    },
  };
}
