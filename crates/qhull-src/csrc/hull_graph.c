/* The convex hull of a 3-D point set as MuJoCo's compiler asks qhull for it (mjCMesh::MakeGraph,
 * src/user/user_mesh.cc: options "qhull Qt", then qh_triangulate and qh_vertexneighbors), written
 * out as MuJoCo's mesh graph with qhull's point ids:
 *
 *   graph[0] = numvert, graph[1] = numface,
 *   vert_edgeadr[numvert], vert_globalid[numvert],
 *   edge_localid[numvert + 3 numface]   (neighbour point ids, -1 after each vertex's list),
 *   face_globalid[3 numface]            (point ids, flipped where qhull's facet is toporient).
 *
 * The edge entries are point ids here; the caller maps them to hull vertex indices. Written for
 * lagrange (crates/qhull-src); the only entry point is lagrange_qhull_graph. */

#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#include "libqhull_r/qhull_ra.h"

/* Status codes (mirrored in src/lib.rs). */
#define LQ_OK 0
#define LQ_QHULL_ERROR 1     /* qhull longjmp'ed: its error code is in *qhull_code */
#define LQ_BAD_POINT_ID 2    /* a vertex's point id outside the input (qhull added a point) */
#define LQ_NOT_TRIANGLE 3    /* a facet with other than 3 vertices after qh_triangulate */
#define LQ_CAPACITY 4        /* the graph does not fit in the caller's buffer */
#define LQ_BAD_INPUT 5       /* fewer than 4 points or a null pointer */

/* Runs qhull ("qhull Qt", with " Q9 TA<maxhullvert-4>" when maxhullvert > -1) on `npoints` points
 * (x, y, z interleaved; not modified) and writes the graph into `graph` (`capacity` ints).
 * Returns an LQ_* code; on LQ_QHULL_ERROR, *qhull_code holds qhull's exit code. Never longjmps
 * past its own frame: qhull's errors return here through its errexit. */
int lagrange_qhull_graph(const double *points, int npoints, int maxhullvert, int *graph,
                         long capacity, int *qhull_code) {
  qhT qh_qh;
  qhT *qh = &qh_qh;
  char options[64];
  volatile int status = LQ_OK;
  int exitcode, curlong, totlong;

  *qhull_code = 0;
  if (!points || !graph || npoints < 4 || capacity < 2) return LQ_BAD_INPUT;
  if (maxhullvert > -1) {
    snprintf(options, sizeof(options), "qhull Qt Q9 TA%d", maxhullvert - 4);
  } else {
    snprintf(options, sizeof(options), "qhull Qt");
  }

  /* qhull reports its errors on the error file; it prints nothing otherwise. */
  qh_zero(qh, stderr);
  qh_init_A(qh, stdin, stdout, stderr, 0, NULL);
  exitcode = setjmp(qh->errexit);
  qh->NOerrexit = False;
  if (!exitcode) {
    facetT *facet;
    vertexT *vertex, *vertex1, **vertex1p;
    int numvert, numface, i, adr;
    int *vert_edgeadr, *vert_globalid, *edge_localid, *face_globalid;
    long size;

    qh_initflags(qh, options);
    /* qhull reads the points in place (no option here rescales them) */
    qh_init_B(qh, (coordT *)points, npoints, 3, False);
    qh_qhull(qh);
    qh_triangulate(qh);
    qh_vertexneighbors(qh);

    numvert = qh->num_vertices;
    numface = qh->num_facets;
    size = 2 + 3 * (long)numvert + 6 * (long)numface;
    if (size > capacity) {
      status = LQ_CAPACITY;
    } else {
      graph[0] = numvert;
      graph[1] = numface;
      vert_edgeadr = graph + 2;
      vert_globalid = graph + 2 + numvert;
      edge_localid = graph + 2 + 2 * numvert;
      face_globalid = graph + 2 + 3 * numvert + 3 * numface;

      /* each vertex: its neighbours through its facets, in qhull's set orders, once each */
      i = adr = 0;
      FORALLvertices {
        int pid = qh_pointid(qh, vertex->point);
        int start = adr;
        facetT **facetp;
        if (pid < 0 || pid >= npoints || i >= numvert) {
          status = LQ_BAD_POINT_ID;
          break;
        }
        vert_edgeadr[i] = adr;
        vert_globalid[i] = pid;
        FOREACHsetelement_(facetT, vertex->neighbors, facet) {
          int cnt = 0;
          FOREACHsetelement_(vertexT, facet->vertices, vertex1) {
            int pid1 = qh_pointid(qh, vertex1->point);
            cnt++;
            if (pid1 < 0 || pid1 >= npoints) {
              status = LQ_BAD_POINT_ID;
              break;
            }
            if (pid != pid1) {
              int j;
              for (j = start; j < adr; j++) {
                if (pid1 == edge_localid[j]) break;
              }
              if (j >= adr) {
                if (adr >= numvert + 3 * numface) {
                  status = LQ_CAPACITY;
                  break;
                }
                edge_localid[adr++] = pid1;
              }
            }
          }
          if (status != LQ_OK) break;
          if (cnt != 3) {
            status = LQ_NOT_TRIANGLE;
            break;
          }
        }
        if (status != LQ_OK) break;
        if (adr >= numvert + 3 * numface) {
          status = LQ_CAPACITY;
          break;
        }
        edge_localid[adr++] = -1;
        i++;
      }
      if (status == LQ_OK && (i != numvert || adr != numvert + 3 * numface)) status = LQ_CAPACITY;

      /* each facet: its three point ids, the first two swapped where qhull's facet is toporient */
      adr = 0;
      if (status == LQ_OK) {
        FORALLfacets {
          int ii = 0;
          int ind[3] = {0, 1, 2};
          if (facet->toporient) {
            ind[0] = 1;
            ind[1] = 0;
          }
          if (adr + 3 > 3 * numface) {
            status = LQ_NOT_TRIANGLE;
            break;
          }
          FOREACHsetelement_(vertexT, facet->vertices, vertex1) {
            if (ii >= 3) {
              status = LQ_NOT_TRIANGLE;
              break;
            }
            face_globalid[adr + ind[ii++]] = qh_pointid(qh, vertex1->point);
          }
          if (status != LQ_OK) break;
          if (ii != 3) {
            status = LQ_NOT_TRIANGLE;
            break;
          }
          adr += 3;
        }
      }
    }
  } else {
    status = LQ_QHULL_ERROR;
    *qhull_code = exitcode;
  }
  qh->NOerrexit = True;
  qh_freeqhull(qh, !qh_ALL);
  qh_memfreeshort(qh, &curlong, &totlong);
  return status;
}
